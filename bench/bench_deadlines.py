"""Planning with time bounds: how far the compiled plans are from the proven earliest times,
and what the proof and the per-bound slack cost.

For each mission a deadline far in the future is added (``F[0,100000] goal``), the mission is
compiled, and the table shows: the time the simulated trajectory first enters the goal, the
earliest any trajectory can (the shortest path at full speed, from
:func:`tlmpc.planning.deadlines.deadline_proofs` asked with a deadline of 0), their ratio (a
deadline in between is answered P051, below the earliest P050), how the shortest path was
searched (``path corners``: exact among that many corners; ``straight``: obstacles ignored,
past the corner limit), and median CPU seconds of the proof search and of the per-bound slacks
(one bisection of 40 exact evaluations per bound; CPU time of the process, since on a shared
machine wall time measures the other jobs too).

A second table compares the metrics the plan minimises: the same missions compiled with
``options.cost: length`` and ``options.cost: time`` in one run, each plan's first entry into
the goal over the earliest possible time, with the medians over the missions.

``python bench/bench_deadlines.py`` prints the two markdown tables.
"""

from __future__ import annotations

import functools
import itertools
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench.workloads import grid_of_rooms, sequence_avoiding  # noqa: E402


def _missions() -> list[tuple[str, dict[str, Any], str, str]]:
    """(name, mission document, goal, the rest of the task in LTL)."""
    deadline = yaml.safe_load((ROOT / "specs" / "deadline.yaml").read_text())
    example1 = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    rows = [
        ("deadline (dock)", deadline, "dock", "G !hazard"),
        ("example1 (p4)", example1, "p4", "G !p2"),
    ]
    for n in (5, 12, 34):
        grid = grid_of_rooms(n)
        rows.append((f"grid {n}x{n}", grid, f"r{n - 1}_{(n - 1) // 3}", ""))
    avoid = sequence_avoiding(10, 50)
    rest = " & ".join(f"G !obs{k}" for k in range(50))
    rows.append(("sequence-avoid (room9)", avoid, "room9", rest))
    return rows


def _median(function: Any, repeats: int) -> tuple[Any, float]:
    times, value = [], None
    for _ in range(repeats):
        started = time.process_time()
        value = function()
        times.append(time.process_time() - started)
    return value, statistics.median(times)


def _entry(trace: dict[str, Any], goal: str) -> float | None:
    """The first time the trace's polyline touches the closed goal (None: never)."""
    import shapely

    region = shapely.Polygon(trace["regions"][goal])
    for (t0, x0, y0), (t1, x1, y1) in itertools.pairwise(trace["points"]):
        segment = shapely.LineString([(x0, y0), (x1, y1)])
        if segment.intersects(region):
            hit = segment.intersection(region)
            along = min(segment.project(shapely.Point(c)) for c in hit.coords)
            return float(t0 + (t1 - t0) * along / max(segment.length, 1e-300))
    return None


def run_metrics(repeats: int = 3) -> list[dict[str, Any]]:
    """The plan's first entry into the goal over the earliest possible time, planned with
    ``options.cost: length`` and ``time`` side by side (one row per mission, then the
    medians), with the time metric's rounds and the median CPU seconds of each compile."""
    from tlmpc.mission import load_mission_text
    from tlmpc.pipeline.stages import WITNESS, compile_mission
    from tlmpc.planning import deadlines
    from tlmpc.planning.mission import abstraction_for

    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as folder:
        for name, document, goal, rest in _missions():
            document = dict(document)
            document.pop("task", None)
            far = f"F[0,100000] {goal}" + (f" & {rest}" if rest else "")
            document["ltl"] = far.replace("100000", "0")
            mission = load_mission_text(yaml.safe_dump(document, sort_keys=False), "m.yaml")
            proofs = deadlines.deadline_proofs(mission, abstraction_for(mission, 0.0, deep=False))
            earliest = proofs[0].earliest if proofs else 0.0
            row: dict[str, Any] = {"mission": name, "earliest possible (s)": round(earliest, 2)}
            for metric in ("length", "time"):
                document["ltl"] = far
                document["options"] = {**(document.get("options") or {}), "cost": metric}
                text = yaml.safe_dump(document, sort_keys=False)
                path = Path(folder) / "m.yaml"
                result, seconds = _median(
                    functools.partial(compile_mission, path, text=text, figures=()), repeats
                )
                entry = _entry(result.artifacts["trace.json"], goal)
                row[f"{metric}: enters (s)"] = round(entry or float("nan"), 2)
                row[f"{metric} / earliest"] = (
                    round((entry or 0.0) / earliest, 3) if earliest else None
                )
                row[f"{metric}: compile s"] = round(seconds, 3)
                if metric == "time":
                    row["time rounds"] = result.compilation.get(WITNESS).stats.get("time_rounds")
            rows.append(row)
    ratios = {
        key: statistics.median(r[key] for r in rows if r[key] is not None)
        for key in ("length / earliest", "time / earliest")
    }
    rows.append({"mission": "median", **{k: round(v, 3) for k, v in ratios.items()}})
    return rows


def run(repeats: int = 3) -> list[dict[str, Any]]:
    """One row per mission."""

    from tlmpc.ltl.ast import Prop
    from tlmpc.ltl.bounds import untimed_skeleton
    from tlmpc.mission import load_mission_text
    from tlmpc.pipeline.stages import compile_mission
    from tlmpc.planning import deadlines
    from tlmpc.planning.explain import invariant_mask
    from tlmpc.planning.mission import abstraction_for
    from tlmpc.verify.trace_input import from_document
    from tlmpc.verify.verdict import bound_slacks

    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, document, goal, rest in _missions():
            document = dict(document)
            document.pop("task", None)
            far = f"F[0,100000] {goal}" + (f" & {rest}" if rest else "")
            document["ltl"] = far
            text = yaml.safe_dump(document, sort_keys=False)
            result = compile_mission(Path(folder) / "m.yaml", text=text)
            trace = result.artifacts["trace.json"]
            entry = _entry(trace, goal)
            document["ltl"] = far.replace("100000", "0")
            mission = load_mission_text(yaml.safe_dump(document, sort_keys=False), "m.yaml")
            mesh = abstraction_for(mission, 0.0, deep=False)
            proofs, proof_s = _median(
                functools.partial(deadlines.deadline_proofs, mission, mesh), repeats
            )
            earliest = proofs[0].earliest if proofs else 0.0
            free = deadlines._Free(
                mesh,
                invariant_mask(mesh, untimed_skeleton(mission.formula)),
                mission.robot.start,
            )
            target = deadlines._goal(free, Prop(goal), mission.options.boundary)
            paths = deadlines._Paths(free, [target])
            _, slack_s = _median(
                functools.partial(bound_slacks, from_document(dict(trace))), repeats
            )
            rows.append(
                {
                    "mission": name,
                    "triangles": mesh.num_triangles,
                    "plan enters goal (s)": round(entry or float("nan"), 2),
                    "earliest possible (s)": round(earliest, 2),
                    "plan / earliest": round((entry or 0.0) / earliest, 2) if earliest else None,
                    "path corners": len(paths.nodes) if paths.exact else "straight",
                    "proof s": round(proof_s, 3),
                    "slacks s": round(slack_s, 3),
                }
            )
    return rows


if __name__ == "__main__":
    from bench.tables import markdown_table

    print(markdown_table(run()))
    print()
    print(markdown_table(run_metrics()))
