"""Disturbed closed-loop runs: how many seeded runs satisfy their task, per spec and model.

Each shipped spec is compiled with ``robot.disturbance`` = a tenth of its ``max_speed`` (and
once as a unicycle with offset 0.1), then simulated through the runtime executor under random
disturbances (SEEDS seeds) and the adversary, |w| <= the declared bound; and once more with
random pushes of four times the bound.  Every trace is checked by the independent verifier.

    python bench/bench_disturbed.py [SEEDS]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

SPECS = ("example1", "example6", "example7", "example8", "patrol", "reach-avoid")


def _row(label: str, compiled: Any, model: str, bound: float, seeds: int) -> list[str]:
    import tlmpc
    from tlmpc.runtime import make_disturbance, run_closed_loop
    from tlmpc.runtime.closed_loop import default_dt
    from tlmpc.verify import verify_document

    satisfied = recovered = samples = 0
    started = time.perf_counter()
    for seed in range(seeds):
        executor = tlmpc.executor(compiled)
        hold = 10 * default_dt(executor.plan, executor.mission.robot.max_speed + bound)
        run = run_closed_loop(
            executor, make_disturbance(model, bound, seed, hold), bound=bound, cycles=2
        )
        satisfied += verify_document(run.trace).satisfied
        recovered += bool(run.recoveries)
        samples += run.samples
    seconds = time.perf_counter() - started
    return [
        label,
        model,
        f"{bound:g}",
        str(seeds),
        f"{satisfied}/{seeds}",
        str(recovered),
        str(samples // seeds),
        f"{seconds / seeds:.2f}",
    ]


def main() -> int:
    import yaml

    import tlmpc

    seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    header = ["spec", "model", "|w| <=", "runs", "satisfied", "recovered", "samples", "s/run"]
    rows: list[list[str]] = []
    for name in SPECS:
        document = yaml.safe_load((ROOT / "specs" / f"{name}.yaml").read_text())
        bound = 0.1 * float(document["robot"].get("max_speed", 1.0))
        document["robot"]["disturbance"] = bound
        compiled = tlmpc.compile(document)
        rows.append(_row(name, compiled, "random", bound, seeds))
        rows.append(_row(name, compiled, "adversarial", bound, 1))
        rows.append(_row(name + " (4x bound)", compiled, "random", 4 * bound, seeds))
        document["robot"].update(model="unicycle", offset=0.1)
        unicycle = tlmpc.compile(document)
        rows.append(_row(name + " (unicycle)", unicycle, "random", bound, seeds))
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    for row in [header, ["-" * w for w in widths], *rows]:
        print(" | ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
