"""A finely drawn region against a densely sampled trace: the verifier's distances with and
without the index over the region's ring.

``python bench/bench_large_regions.py`` prints one table: for rings of 1,000 to 12,000 corners
(a star of varying radius round the map's centre) and 200,000 samples of a path that crosses
the map through the region, the CPU seconds (median of three, the two measured interleaved) of
GEOS's distance from every sample to the ring and of :func:`tlmpc.verify.robustness.
_indexed_ring_distance`, which must give the same numbers (asserted), and their ratio.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np
import shapely

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tlmpc.verify.robustness import _indexed_ring_distance

SAMPLES = 200_000
ROUNDS = 3


def _ring(corners: int) -> shapely.Polygon:
    rng = np.random.default_rng(corners)
    angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, corners))
    radii = 2.0 * (1.0 - 0.3 * rng.uniform(0.0, 1.0, corners))
    return shapely.Polygon(
        np.stack([8.0 + radii * np.cos(angles), 5.0 + radii * np.sin(angles)], axis=1)
    )


def _path() -> np.ndarray:
    t = np.linspace(0.0, 1.0, SAMPLES)
    return np.stack([16.0 * t, 5.0 + 3.0 * np.sin(6.0 * t)], axis=1)


def main() -> None:
    geoms = shapely.points(_path())
    print("| ring corners | GEOS s | indexed s | ratio |")
    print("|---|---|---|---|")
    for corners in (1_000, 3_000, 6_000, 12_000):
        ring = _ring(corners).exterior
        plain, indexed = [], []
        for _ in range(ROUNDS):
            started = time.process_time()
            expected = shapely.distance(ring, geoms)
            plain.append(time.process_time() - started)
            started = time.process_time()
            found = _indexed_ring_distance(ring, geoms)
            indexed.append(time.process_time() - started)
            assert np.array_equal(found, expected)
        a, b = statistics.median(plain), statistics.median(indexed)
        print(f"| {corners:,} | {a:.3f} | {b:.3f} | {a / b:.1f} |")


if __name__ == "__main__":
    main()
