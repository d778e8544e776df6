"""How close the simulated trajectory comes to the shortest path, before and after the
controllers follow the channel's shortest path.

For every workload the mission is compiled twice through the whole pipeline: *before* with the
vertex program's fields alone (``synthesize(..., follow=False)``), *after* with the fields that
follow the channel (the default).  Measured on the exact closed-loop trajectory (trace.json,
each sampled piece refined by the step's own matrix exponential):

* **length ratio**: the trajectory's length until the task is met (the first entry into its
  last target) over the shortest path from the start touching the same targets in the same
  order, keeping the body's clearance and off the avoided regions (tests/oracles/
  shortest_paths.py: a visibility graph on shapely geometry, independent of tlmpc);
* **time ratio**: the time the task is met over that shortest length at ``max_speed``;
* **lap ratio** (patrols): one lap of the trajectory's cycle over the shortest closed tour
  touching the targets in the lap's cyclic order;
* **robustness**: the verifier's (how far the trajectory stays from every label boundary that
  would change the verdict): a path that hugs the shortest one passes closer to them.

Targets are given per workload as ordered groups: the regions of a group are taken in the
order the trajectory first enters them (so the oracle compares the same visiting order; a
better order is the planner's business, not the controllers').  Prints one table.
Run: ``python bench/bench_geodesic.py`` (about a minute).
"""

from __future__ import annotations

import functools
import math
import random
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from unittest import mock

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
for extra in (ROOT, ROOT / "tests" / "oracles"):
    if str(extra) not in sys.path:
        sys.path.insert(0, str(extra))


@dataclass(frozen=True)
class Workload:
    """A mission and what its task asks: ordered groups of targets, regions to avoid."""

    name: str
    mission: Any  # a path or a mission dict
    groups: tuple[tuple[str, ...], ...]
    avoid: tuple[str, ...] = ()
    patrol: bool = False


def shipped() -> list[Workload]:
    """The shipped specs (Example 1's 'avoiding p2 and p3' is left out of the oracle: its
    path is then a lower bound and the ratio an upper bound)."""
    specs = ROOT / "specs"
    rooms = tuple(f"r{k}" for k in range(1, 7))
    return [
        Workload("example1", specs / "example1.yaml", (("p2",), ("p3",), ("p4",), ("p1",))),
        Workload("example6", specs / "example6.yaml", (rooms,)),
        Workload(
            "example7",
            specs / "example7.yaml",
            (("r2",), ("r1",), ("r3", "r4", "r5")),
            avoid=("o1", "o2", "o3"),
        ),
        Workload("example8", specs / "example8.yaml", (("r31_13", "r12_30"),)),
        Workload("reach-avoid", specs / "reach-avoid.yaml", (("dock",), ("home",)), ("hazard",)),
        Workload(
            "patrol",
            specs / "patrol.yaml",
            (("alpha", "bravo", "charlie"),),
            avoid=("lake",),
            patrol=True,
        ),
    ]


def _rect(x: float, y: float, w: float, h: float) -> list[float]:
    return [round(x, 3), round(y, 3), round(x + w, 3), round(y + h, 3)]


def generated(seed: int, *, radius: float = 0.0, patrol: bool = False) -> Workload:
    """A random room: a 16 x 10 box with 5 to 9 rectangular pillars, 3 goal regions and an
    avoided pond, start in a corner; visit the goals in sequence, or patrol them."""
    rng = random.Random(seed)
    holes: list[list[float]] = []
    while len(holes) < rng.randint(5, 9):
        w, h = rng.uniform(0.4, 2.5), rng.uniform(0.4, 2.5)
        holes.append(_rect(rng.uniform(2.0, 14.0 - w), rng.uniform(1.0, 9.0 - h), w, h))
    regions = {
        "a": {"rect": _rect(13.5, 0.5, 2.0, 2.0)},
        "b": {"rect": _rect(13.5, 7.5, 2.0, 2.0)},
        "c": {"rect": _rect(7.0, 8.6, 2.0, 1.2)},
        "pond": {"rect": _rect(rng.uniform(3.0, 11.0), rng.uniform(0.2, 1.0), 1.5, 1.0)},
    }
    robot: dict[str, Any] = {"start": [0.8, 0.8], "max_speed": 1.0}
    if radius:
        robot["radius"] = radius
    task = ["patrol a, b and c"] if patrol else ["visit a then b then c"]
    document = {
        "version": 1,
        "name": f"room-{seed}",
        "workspace": {"boundary": {"rect": [0, 0, 16, 10]}, "holes": [{"rect": h} for h in holes]},
        "regions": regions,
        "robot": robot,
        "task": [*task, "avoid pond"],
    }
    name = f"room-{seed}" + (f" r={radius:g}" if radius else "") + (" patrol" if patrol else "")
    groups = (("a", "b", "c"),) if patrol else (("a",), ("b",), ("c",))
    return Workload(name, document, groups, avoid=("pond",), patrol=patrol)


def _compile(workload: Workload, follow: bool) -> tuple[Any, float]:
    """The compiled mission and the length of the path its fields follow (the channel's
    shortest path with the portal insets; nan before)."""
    import importlib

    from tlmpc.api import compile as compile_mission

    control = importlib.import_module("tlmpc.control")
    module = importlib.import_module("tlmpc.control.synthesize")
    original, guides = module.path_guides, []

    def recorded(*args: Any) -> Any:
        guides[:] = original(*args)
        return list(guides)

    fields = functools.partial(module.synthesize, follow=follow)
    with (
        mock.patch.object(control, "synthesize", fields),
        mock.patch.object(module, "path_guides", recorded),
    ):
        mission = workload.mission
        compiled = compile_mission(str(mission) if isinstance(mission, Path) else mission)
    length = sum(math.dist(g.entry, g.exit) for g in guides if g is not None)
    return compiled, length if guides else float("nan")


def _fine_trajectory(artifacts: Any, pieces: int = 8) -> tuple[Any, Any]:
    """Times and points of the trajectory, each sampled piece subdivided exactly."""
    from scipy.linalg import expm

    trace = artifacts["trace.json"]
    controllers = artifacts["controllers.json"]["steps"]
    samples = np.asarray(trace["points"], dtype=np.float64)
    steps = trace["steps"]
    times, points = [samples[0, 0]], [samples[0, 1:]]
    for k in range(1, len(samples)):
        t0, t1 = samples[k - 1, 0], samples[k, 0]
        step = controllers[steps[k]]
        if steps[k] == steps[k - 1] and step.get("kind", "affine") == "affine" and t1 > t0:
            matrix = np.zeros((3, 3))
            matrix[:2, :2] = np.asarray(step["K"])
            matrix[:2, 2] = np.asarray(step["g"])
            start = np.append(samples[k - 1, 1:], 1.0)
            for j in range(1, pieces):
                tau = (t1 - t0) * j / pieces
                times.append(t0 + tau)
                points.append((expm(tau * matrix) @ start)[:2])
        times.append(t1)
        points.append(samples[k, 1:])
    return np.asarray(times), np.asarray(points)


def _travelled(artifacts: Any) -> float:
    """The whole trajectory's length (to the end of the trace)."""
    _, points = _fine_trajectory(artifacts)
    return float(np.hypot(*np.diff(points, axis=0).T).sum())


def _order(points: Any, shapes: dict[str, Any], groups: Any, begin: int = 0) -> tuple[list, int]:
    """The targets in the order the trajectory meets them (group by group), and the index of
    the point where the last one is first entered (-1 when never)."""
    import shapely

    order: list[str] = []
    index = begin
    for group in groups:
        pending = set(group)
        while pending:
            if index >= len(points):
                return order, -1
            inside = [n for n in sorted(pending) if shapes[n].covers(shapely.Point(points[index]))]
            if inside:
                order.extend(inside)
                pending -= set(inside)
                if not pending:
                    break
            index += 1
    return order, index


_BEST: dict[tuple[str, tuple[str, ...], bool], float] = {}


def _best(key: tuple[str, tuple[str, ...], bool], free: Any, targets: Any, start: Any) -> float:
    """The oracle's length for one workload and visiting order (computed once per order)."""
    from shortest_paths import VisibilityOracle

    if key not in _BEST:
        oracle = VisibilityOracle(free, targets, start)
        _BEST[key] = oracle.tour_length() if key[2] else oracle.path_length()
    return _BEST[key]


def _measure(workload: Workload, compiled: Any) -> dict[str, float]:
    import shapely

    from tlmpc.mission import load_mission, load_mission_text
    from tlmpc.mission.body import body_radius
    from tlmpc.mission.cspace import workspace_free_space

    mission_source = workload.mission
    if isinstance(mission_source, Path):
        mission = load_mission(mission_source)
    else:
        import yaml

        mission = load_mission_text(yaml.safe_dump(mission_source), "generated.yaml")
    shapes = {r.name: shapely.Polygon(r.polygon) for r in mission.regions}
    free = workspace_free_space(mission)
    for name in workload.avoid:
        free = free.difference(shapes[name])
    radius = body_radius(mission.robot)
    if radius > 0:
        free = free.buffer(-radius, quad_segs=16)
    times, points = _fine_trajectory(compiled.artifacts)
    steps_travelled = np.hypot(*np.diff(points, axis=0).T)
    cumulative = np.concatenate([[0.0], np.cumsum(steps_travelled)])
    speed = mission.robot.max_speed
    row: dict[str, float] = {}
    if workload.patrol:
        trace = compiled.artifacts["trace.json"]
        loop_time = trace["points"][trace["loop_start"]][0]
        lap_start = int(np.searchsorted(times, loop_time))
        order, _ = _order(points, shapes, workload.groups, lap_start)
        lap = float(cumulative[-1] - cumulative[lap_start])
        key = (workload.name, tuple(order), True)
        best = _best(key, free, tuple(shapes[n] for n in order), tuple(points[0]))
        row["lap"] = lap / best
        row["lap time"] = float(times[-1] - times[lap_start]) / (best / speed)
        return row
    order, met = _order(points, shapes, workload.groups)
    if met < 0:
        return {"length": float("nan"), "time": float("nan")}
    key = (workload.name, tuple(order), False)
    best = _best(key, free, tuple(shapes[n] for n in order), tuple(mission.robot.start))
    row["length"] = float(cumulative[met]) / best
    row["time"] = float(times[met]) / (best / speed)
    return row


def run(only: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """Rows: every workload's ratios before and after, side by side (``only``: these names)."""
    workloads = [
        *shipped(),
        *(generated(seed) for seed in (1, 2, 3)),
        *(generated(seed, radius=0.2) for seed in (1, 2, 3)),
        *(generated(seed, patrol=True) for seed in (4, 5)),
        generated(6, radius=0.2, patrol=True),
    ]
    rows = []
    for workload in workloads:
        if only and workload.name not in only:
            continue
        row: dict[str, Any] = {"workload": workload.name}
        for label, follow in (("before", False), ("after", True)):
            try:
                compiled, guided = _compile(workload, follow)
                measured = _measure(workload, compiled)
            except Exception as failure:  # a mission this generator made unsolvable
                row["note"] = f"{type(failure).__name__}: {str(failure)[:60]}"
                break
            for key, value in measured.items():
                row[f"{key} {label}"] = round(value, 3)
            row[f"robustness {label}"] = round(compiled.summary["verdict"]["robustness"], 4)
            if follow and not workload.patrol:  # how closely the flow keeps to its path
                row["trajectory / its path"] = round(_travelled(compiled.artifacts) / guided, 3)
        rows.append(row)
    return rows


def _table(rows: list[dict[str, Any]]) -> str:
    columns: list[str] = []
    for row in rows:
        columns += [key for key in row if key not in columns]
    lines = [
        "| " + " | ".join(columns) + " |",
        "|" + "---|" * len(columns),
    ]
    lines += ["| " + " | ".join(str(row.get(c, "")) for c in columns) + " |" for row in rows]
    return "\n".join(lines)


if __name__ == "__main__":
    print(_table(run(tuple(sys.argv[1:]))))
