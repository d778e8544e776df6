"""Stage by stage, before and after: CPU seconds of each compile stage on the grid maps.

``python bench/bench_stages.py --baseline DIR`` compiles each workload (Example 8 and the
``bench.workloads.grid_of_rooms`` maps named by ``--grids``) in a fresh interpreter per tree
and per round, rounds interleaved across the trees so that the machine's load hits both
alike, and prints per stage the median CPU seconds (``time.process_time``: on a shared machine
it moves less than wall time), the whole compile's CPU seconds and peak RSS, and the plan's
cost and length (which must agree between the trees).  The figure is not drawn (the plot
stage is another bench's subject); the collector is paused as ``tlmpc compile`` pauses it.

``--tasks`` adds the planning-only rows of ``bench_planning.py`` on the Example 8 map (the
paper's task, cover-6, patrol-4).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent

GRIDS = {"10k": 35, "100k": 112, "300k": 194, "1M": 354}
STAGE_NAMES = ("load", "abstraction", "automaton", "plan", "control", "simulate", "verify")

#: Run in a fresh interpreter: every stage but the figure, one after the other.
STAGES_PROGRAM = """
import gc, json, resource, sys, time
from pathlib import Path
gc.disable()
started = time.process_time()
from tlmpc.pipeline.stages import STAGES, Compilation, run_stages
compilation = Compilation(source=Path(sys.argv[1]), text=None, figures=())
cpu = {}
plan = {}
for stage in STAGES:
    if stage.name == "plot":
        continue
    before = time.process_time()
    result = run_stages([stage], compilation)
    cpu[stage.name] = time.process_time() - before
    compilation = result.compilation
    if stage.name == "plan":
        plan = dict(result.reports[0].sizes)
print(json.dumps({
    "cpu": cpu,
    "total": time.process_time() - started,
    "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    "plan": plan,
}))
"""

TASKS_PROGRAM = """
import json, sys, time
from bench.bench_planning import ROOMS, _example8
from tlmpc.automata import translate
from tlmpc.ltl import parse_ltl
from tlmpc.planning import plan
mission, abstraction = _example8()
rows = {}
for name, text in [
    ("paper", str(mission.formula)),
    ("cover-6", " & ".join(f"F {r}" for r in ROOMS[:6])),
    ("patrol-4", " & ".join(f"G F {r}" for r in ROOMS[:4])),
]:
    formula = parse_ltl(text)
    automaton = translate(formula, letters=abstraction.letters)
    before = time.process_time()
    witness = plan(abstraction, automaton, formula=formula, options=mission.options,
                   start_point=mission.robot.start)
    rows[name] = {"cpu": time.process_time() - before, "cost": round(witness.cost, 6),
                  "length": f"{len(witness.prefix)}+{len(witness.cycle)}",
                  "reached": witness.stats["product_reached"]}
print(json.dumps(rows))
"""


def _environment(tree: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = f"{tree}{os.pathsep}{ROOT}"
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _run(tree: Path, program: str, *args: str) -> dict[str, Any]:
    # Not from ROOT: ``-c`` puts the working directory first on sys.path.
    done = subprocess.run(
        [sys.executable, "-c", program, *args],
        capture_output=True,
        text=True,
        env=_environment(tree),
        cwd=tempfile.gettempdir(),
        check=False,
    )
    if done.returncode != 0:
        raise RuntimeError(f"{tree}: {done.stderr[-2000:]}")
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def _write_grid(n: int, directory: Path) -> Path:
    """The grid mission, written by another interpreter: a child started from a large parent
    would report the parent's size as its own peak (ru_maxrss survives exec)."""
    program = (
        "import sys; from pathlib import Path; from bench.workloads import grid_of_rooms, "
        "write_mission; print(write_mission(grid_of_rooms(int(sys.argv[1])), Path(sys.argv[2])))"
    )
    done = subprocess.run(
        [sys.executable, "-c", program, str(n), str(directory)],
        capture_output=True,
        text=True,
        env=_environment(ROOT),
        cwd=tempfile.gettempdir(),
        check=True,
    )
    return Path(done.stdout.strip().splitlines()[-1])


def _median(values: list[float]) -> float:
    return statistics.median(values)


def comparison_parser(script: str, description: str | None, rounds: int) -> argparse.ArgumentParser:
    """The flags every before/after bench shares: ``--baseline``, ``--grids``, ``--rounds``."""
    parser = argparse.ArgumentParser(prog=f"python bench/{script}", description=description)
    parser.add_argument("--baseline", type=Path, help="another tlmpc source tree to compare")
    parser.add_argument("--grids", default="100k", help="of: " + ", ".join(GRIDS))
    parser.add_argument("--rounds", type=int, default=rounds)
    return parser


def trees_of(args: argparse.Namespace) -> dict[str, Path]:
    """This tree, and the ``--baseline`` tree when given, by column name."""
    trees = {"tlmpc": ROOT}
    if args.baseline is not None:
        trees["baseline"] = args.baseline.resolve()
    return trees


def workloads_of(grids: str, directory: Path) -> dict[str, Path]:
    """Example 8 and the grid missions named by ``grids`` (written into ``directory``)."""
    workloads = {"example8": ROOT / "specs" / "example8.yaml"}
    for name in [g for g in grids.split(",") if g]:
        workloads[f"grid {name}"] = _write_grid(GRIDS[name], directory)
    return workloads


def main(argv: list[str] | None = None) -> int:
    parser = comparison_parser("bench_stages.py", __doc__, rounds=3)
    parser.add_argument("--tasks", action="store_true", help="planning-only rows on Example 8")
    args = parser.parse_args(argv)
    trees = trees_of(args)
    for tree in trees.values():
        subprocess.run(
            [sys.executable, "-m", "compileall", "-q", str(tree / "tlmpc")],
            env=_environment(tree),
            capture_output=True,
            check=True,
        )
    with tempfile.TemporaryDirectory(prefix="tlmpc-stages-") as tmp:
        workloads = workloads_of(args.grids, Path(tmp))
        header = " | ".join(STAGE_NAMES)
        print(f"| workload | tree | {header} | total CPU s | peak MB | plan |")
        print("|---|---|" + "---:|" * (len(STAGE_NAMES) + 2) + "---|")
        for workload, path in workloads.items():
            runs: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
            for _ in range(args.rounds):
                for name, tree in trees.items():
                    print(f"{workload} {name} ...", file=sys.stderr, flush=True)
                    runs[name].append(_run(tree, STAGES_PROGRAM, str(path)))
            for name, results in runs.items():
                stages = [_median([r["cpu"][s] for r in results]) for s in STAGE_NAMES]
                plan = results[0]["plan"]
                print(
                    f"| {workload} | {name} | "
                    + " | ".join(f"{s:.3f}" for s in stages)
                    + f" | {_median([r['total'] for r in results]):.2f}"
                    + f" | {max(r['peak_mb'] for r in results):.0f}"
                    + f" | cost {plan.get('cost')}, prefix {plan.get('prefix')}, "
                    f"reached {plan.get('reached')} |"
                )
        if args.tasks:
            print("\n| task on Example 8 | tree | plan CPU s | cost | lasso | reached |")
            print("|---|---|---:|---:|---|---:|")
            task_runs: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
            for _ in range(args.rounds):
                for name, tree in trees.items():
                    task_runs[name].append(_run(tree, TASKS_PROGRAM))
            for task in task_runs["tlmpc"][0]:
                for name, results in task_runs.items():
                    row = results[0][task]
                    cpu = _median([r[task]["cpu"] for r in results])
                    print(
                        f"| {task} | {name} | {cpu:.3f} | {row['cost']} | {row['length']} | "
                        f"{row['reached']} |"
                    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
