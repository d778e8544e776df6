"""Abstraction benchmark: Example 8 (quality off) and grids of rooms up to ~100k triangles.

``python bench/bench_abstraction.py`` prints a markdown table: triangles, median seconds of the
whole stage (triangulation, labels, components) and the stage's peak traced memory.
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench.workloads import grid_of_rooms, write_mission  # noqa: E402


def _measure(mission: Any, repeats: int) -> dict[str, Any]:
    from tlmpc.abstraction import build_abstraction

    build_abstraction(mission)  # warm: imports and caches
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        abstraction = build_abstraction(mission)
        times.append(time.perf_counter() - started)
    tracemalloc.start()
    build_abstraction(mission)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return {
        "triangles": abstraction.num_triangles,
        "letters": len(abstraction.letters),
        "seconds (median)": round(statistics.median(times), 4),
        "peak traced MB": round(peak / 2**20, 1),
        "bytes per triangle": round(peak / abstraction.num_triangles),
    }


def run(repeats: int = 3) -> list[dict[str, Any]]:
    """Rows for bench/run.py."""
    from tlmpc.mission import load_mission

    rows = [
        {
            "workload": "example8 (quality off)",
            **_measure(load_mission(ROOT / "specs" / "example8.yaml"), repeats),
        }
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for n in (11, 35, 112):
            mission = load_mission(write_mission(grid_of_rooms(n), Path(tmp)))
            rows.append({"workload": f"grid {n}x{n}", **_measure(mission, repeats)})
    return rows


if __name__ == "__main__":
    from bench.tables import markdown_table

    print(markdown_table(run()))
