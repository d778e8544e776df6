"""Verifier benchmark: a long trace against a 10-conjunct task on a map of many square regions.

The map is a 40 x 25 grid of 1,000 unit squares with small gaps (so the path crosses region
boundaries constantly); the path is a lawnmower sweep sampled at 100,000 points.  Timed:
``verify_document`` end to end (validation, piece splitting, evaluation, robustness).
"""

from __future__ import annotations

import statistics
import time
from typing import Any

import numpy as np


def workload(samples: int = 100_000, cols: int = 40, rows: int = 25) -> dict[str, Any]:
    """A ``tlmpc.trace/1`` document: lawnmower path over a grid of square regions."""
    regions: dict[str, list[list[float]]] = {}
    gap = 0.1
    for i in range(cols):
        for j in range(rows):
            x0, y0 = i + gap, j + gap
            x1, y1 = i + 1 - gap, j + 1 - gap
            regions[f"r{i}_{j}"] = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    # Lawnmower: sweep each row left to right / right to left, step up between rows.
    per_row = samples // rows
    xs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    for j in range(rows):
        x = np.linspace(0.05, cols - 0.05, per_row)
        xs.append(x if j % 2 == 0 else x[::-1])
        ys.append(np.full(per_row, j + 0.5))
    x_all = np.concatenate(xs)
    y_all = np.concatenate(ys)
    n = len(x_all)
    t = np.arange(n, dtype=float) * 0.01
    names = list(regions)
    rng = np.random.default_rng(0)
    picks = [names[k] for k in rng.choice(len(names), size=8, replace=False)]
    conjuncts = [f"F {p}" for p in picks[:6]]
    conjuncts += [f"G !(({picks[6]}) & ({picks[7]}))", f"F ({names[0]} & F {names[-1]})"]
    conjuncts += [f"(!{names[-1]}) U {names[0]}", f"G ({names[5]} -> F {names[6]})"]
    return {
        "format": "tlmpc.trace/1",
        "ltl": " & ".join(f"({c})" for c in conjuncts),
        "regions": regions,
        "workspace": {
            "boundary": [
                [-1.0, -1.0],
                [cols + 1.0, -1.0],
                [cols + 1.0, rows + 1.0],
                [-1.0, rows + 1.0],
            ],
            "holes": [],
        },
        "boundary": "right",
        "max_speed": 10.0,
        "points": np.column_stack([t, x_all, y_all]).tolist(),
        "loop_start": None,
        "end": "stay",
    }


def run(repeats: int = 3) -> list[dict[str, Any]]:
    """Median wall time of ``verify_document`` on the workload."""
    from tlmpc.verify import verify_document

    doc = workload()
    times = []
    verdict = None
    for _ in range(repeats):
        start = time.perf_counter()
        verdict = verify_document(doc)
        times.append(time.perf_counter() - start)
    assert verdict is not None
    return [
        {
            "name": "verify lawnmower",
            "samples": len(doc["points"]),
            "regions": len(doc["regions"]),
            "conjuncts": 10,
            "satisfied": verdict.satisfied,
            "median_s": statistics.median(times),
        }
    ]


if __name__ == "__main__":
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from bench.tables import markdown_table

    print(markdown_table(run()))
