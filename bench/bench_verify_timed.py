"""Verifier benchmark for time bounds: the lawnmower trace of :mod:`bench.bench_verify` against
bounded tasks, with each ending (an open log, a stay, a loop).

Timed: ``verify_document`` end to end; a decided bounded task includes its time robustness
(a bisection of 40 exact evaluations per bounded conjunct).
"""

from __future__ import annotations

import statistics
import time
from typing import Any

TASKS = {
    "deadline": "F[0,300] r0_0",
    "revisit": "G F[0,120] (r0_0 | r39_24)",
    "response": "G(r5_5 -> F[0,60] r6_5) & G !(r1_1 & r2_2)",
    "nested": "F[0,100] (r1_0 & F[0,50] G[0,0.5] r2_0)",
}


def run(repeats: int = 1) -> list[dict[str, Any]]:
    """Median wall time per task and ending."""
    from bench.bench_verify import workload
    from tlmpc.verify import verify_document

    base = workload()
    rows = []
    for name, ltl in TASKS.items():
        for ending, loop in (("open", None), ("stay", None), ("loop", 0)):
            doc = {**base, "ltl": ltl, "end": ending, "loop_start": loop}
            times = []
            verdict = None
            for _ in range(repeats):
                start = time.perf_counter()
                verdict = verify_document(doc)
                times.append(time.perf_counter() - start)
            assert verdict is not None
            rows.append(
                {
                    "task": name,
                    "ending": ending,
                    "samples": len(doc["points"]),
                    "verdict": verdict.outcome,
                    "time_robustness": verdict.time_robustness,
                    "median_s": round(statistics.median(times), 3),
                }
            )
    return rows


if __name__ == "__main__":
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from bench.tables import markdown_table

    print(markdown_table(run()))
