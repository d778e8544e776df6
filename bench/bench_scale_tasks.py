"""Hard tasks at scale: cover-6 while avoiding one room, and patrol-20, on the grid maps.

``python bench/bench_scale_tasks.py`` plans each workload (``bench.workloads.grid_task`` on
``grid_of_rooms`` maps of 10k, 30k and 100k triangles) in a fresh interpreter per run, with
the guided search (the product expanded on demand) and, where the product can be built, with
the built product, and prints a markdown table: the planning stage's CPU seconds
(``time.process_time``; the median of ``--repeats`` runs), the process's peak RSS (mission
loading and the mesh included), the plan's cost (which must agree between the two searches),
the nodes the search reached, the closing searches it made and the guided search's rounds
(steps of its bucket queues: a search along a long lasso takes about one per edge of it).
``--compile`` adds a row per workload for the whole ``tlmpc compile`` (every stage but the
figure) in CPU seconds, and a second table with each stage's CPU seconds (medians);
``--compile-only`` measures the whole compile alone.

``--baseline DIR`` runs every measurement side by side with another tree of the project
(its runs alternate with this tree's, each in a fresh interpreter started in that tree) and
adds its medians and nodes reached as "before" columns; the costs must agree.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

GRIDS = {"10k": 35, "30k": 61, "100k": 112}
TASKS = (("cover", 6), ("patrol", 20))
#: The built product is planned only where it fits the machine (the 100k products do not).
BUILT_UP_TO = ("10k", "30k")

PLAN_PROGRAM = """
import gc, json, resource, sys, time
from pathlib import Path
gc.disable()
from tlmpc.abstraction import build_abstraction
from tlmpc.mission import load_mission
from tlmpc.planning.mission import automaton_for
from tlmpc.planning.plan import plan
mission = load_mission(Path(sys.argv[1]))
abstraction = build_abstraction(mission)
automaton = automaton_for(mission, abstraction)
started = time.process_time()
witness = plan(abstraction, automaton, formula=mission.formula, options=mission.options,
               start_point=mission.robot.start, guided=sys.argv[2] == "guided")
cpu = time.process_time() - started
print(json.dumps({
    "cpu": cpu,
    "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    "cost": witness.cost,
    "triangles": abstraction.num_triangles,
    "states": witness.stats["automaton_states"],
    "reached": witness.stats["product_reached"],
    "nodes": witness.stats["product_nodes"],
    "searches": witness.stats["cycle_searches"],
    "rounds": witness.stats.get("search_rounds"),
    "optimal": witness.stats["optimal"],
    "plan": f"{len(witness.prefix)}+{len(witness.cycle)}",
}))
"""

COMPILE_PROGRAM = """
import gc, json, resource, sys, time
from pathlib import Path
gc.disable()
started = time.process_time()
from tlmpc.pipeline.stages import STAGES, Compilation, run_stages
compilation = Compilation(source=Path(sys.argv[1]), text=None, figures=())
stages = {}
for stage in STAGES:
    if stage.name == "plot":
        continue
    before = time.process_time()
    compilation = run_stages([stage], compilation).compilation
    stages[stage.name] = time.process_time() - before
print(json.dumps({
    "cpu": time.process_time() - started,
    "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    "stages": stages,
}))
"""


def _run(program: str, *arguments: str, tree: Path = ROOT) -> dict[str, Any]:
    # ``python -c`` imports tlmpc from its working directory: the tree measured.
    done = subprocess.run(
        [sys.executable, "-c", program, *arguments],
        capture_output=True,
        text=True,
        cwd=tree,
        check=False,
    )
    if done.returncode != 0:
        return {"error": done.stderr.strip().splitlines()[-1] if done.stderr else "failed"}
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def _side_by_side(
    program: str, arguments: list[str], repeats: int, baseline: Path | None
) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """This tree's runs and the baseline's (empty without one), alternating."""
    mine: list[dict[str, Any]] = []
    before: list[dict[str, Any]] = []
    for _ in range(repeats):
        if baseline is not None:
            before.append(_run(program, *arguments, tree=baseline))
        mine.append(_run(program, *arguments))
    return mine, before


def _median(runs: list[dict[str, Any]], key: str) -> float:
    return round(statistics.median(r[key] for r in runs), 2)


def _stage_row(workload: str, tree: str, runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Each stage's median CPU seconds over ``runs`` (the stages that ran), and their sum."""
    names = [name for name in runs[0]["stages"] if name != "synthesize"]
    row: dict[str, Any] = {"workload": workload, "tree": tree}
    for name in names:
        row[name] = round(statistics.median(r["stages"][name] for r in runs), 2)
    row["whole compile"] = _median(runs, "cpu")
    return row


def rows(
    repeats: int,
    grids: list[str],
    compile_too: bool,
    baseline: Path | None = None,
    plan_too: bool = True,
    stage_table: list[dict[str, Any]] | None = None,
) -> list[dict[str, Any]]:
    """One row per workload and search; with ``stage_table``, the whole compile's stages are
    appended there (this tree's and the baseline's medians)."""
    from bench.workloads import grid_task, write_mission

    table: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for grid in grids:
            for task, count in TASKS:
                path = write_mission(grid_task(GRIDS[grid], task, count), Path(tmp))
                searches = ["guided", "built"] if grid in BUILT_UP_TO else ["guided"]
                if not plan_too:
                    searches = []
                for search in searches:
                    runs, before = _side_by_side(
                        PLAN_PROGRAM, [str(path), search], repeats, baseline
                    )
                    if any("error" in run for run in runs + before):
                        error = next(run["error"] for run in runs + before if "error" in run)
                        table.append(
                            {"workload": f"{task}-{count} {grid}", "search": search, "note": error}
                        )
                        continue
                    last = runs[-1]
                    row: dict[str, Any] = {
                        "workload": f"{task}-{count} {grid}",
                        "search": search,
                        "triangles": last["triangles"],
                        "automaton states": last["states"],
                        "product nodes": last["nodes"],
                        "reached": last["reached"],
                        "closing searches": last["searches"],
                        "rounds": last["rounds"] if last["rounds"] is not None else "-",
                        "plan CPU s": _median(runs, "cpu"),
                        "peak MB": round(max(r["peak_mb"] for r in runs)),
                        "cost": f"{last['cost']:.6f}",
                        "plan": last["plan"],
                        "optimal": last["optimal"],
                    }
                    if before:
                        row["reached before"] = before[-1]["reached"]
                        row["closing searches before"] = before[-1]["searches"]
                        row["rounds before"] = before[-1].get("rounds") or "-"
                        row["plan CPU s before"] = _median(before, "cpu")
                        row["peak MB before"] = round(max(r["peak_mb"] for r in before))
                        row["cost before"] = f"{before[-1]['cost']:.6f}"
                    table.append(row)
                if compile_too:
                    wholes, before = _side_by_side(COMPILE_PROGRAM, [str(path)], repeats, baseline)
                    failed = [run["error"] for run in wholes + before if "error" in run]
                    row = {
                        "workload": f"{task}-{count} {grid}",
                        "search": "whole compile",
                        "note": failed[0] if failed else "every stage but the figure",
                    }
                    if not failed:
                        row["plan CPU s"] = _median(wholes, "cpu")
                        row["peak MB"] = round(max(r["peak_mb"] for r in wholes))
                        if before:
                            row["plan CPU s before"] = _median(before, "cpu")
                            row["peak MB before"] = round(max(r["peak_mb"] for r in before))
                        if stage_table is not None:
                            workload = f"{task}-{count} {grid}"
                            if before:
                                stage_table.append(_stage_row(workload, "before", before))
                            stage_table.append(_stage_row(workload, "now", wholes))
                    table.append(row)
    return table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--grids", nargs="+", default=list(GRIDS), choices=list(GRIDS))
    parser.add_argument("--compile", action="store_true", help="add the whole compile")
    parser.add_argument(
        "--compile-only", action="store_true", help="the whole compile alone (no plan rows)"
    )
    parser.add_argument("--baseline", type=Path, help="another tree, measured side by side")
    arguments = parser.parse_args()
    from bench.tables import markdown_table

    baseline = arguments.baseline.resolve() if arguments.baseline else None
    stages: list[dict[str, Any]] = []
    table = rows(
        arguments.repeats,
        arguments.grids,
        arguments.compile or arguments.compile_only,
        baseline,
        plan_too=not arguments.compile_only,
        stage_table=stages,
    )
    print(markdown_table(table))
    if stages:
        print()
        print("CPU seconds per stage of the whole compile (medians):")
        print()
        print(markdown_table(stages))


if __name__ == "__main__":
    main()
