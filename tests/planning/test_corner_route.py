"""The corner candidate of the ``length`` re-plans (tlmpc.pipeline.corners): the kept plan
planned again on its mesh cut into rings where its path bends round a corner, kept when its
trajectory is shorter and it is not slower than the midpoint plan.

References: the same compile with the candidate switched off (its trace's length until the
task is met, measured here on the trace with shapely), the midpoint plan's exact time, the
verifier's verdict, and a brute-force reading of the channel's turns."""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any, cast
from unittest import mock

import numpy as np
import pytest
import shapely

from tlmpc.abstraction.corner import RING_FRACTION, ring_corners
from tlmpc.control.channel import LABEL_INSET, label_clearance
from tlmpc.control.synthesize import plan_steps
from tlmpc.pipeline import corners, shortest
from tlmpc.pipeline.mintime import measure
from tlmpc.pipeline.stages import MISSION, WITNESS, CompileResult, compile_mission
from tlmpc.planning.mission import Planned

ROOT = Path(__file__).resolve().parents[2]


def _compiled(spec: str, *, rings: bool) -> CompileResult:
    path = str(ROOT / "specs" / spec)
    if rings:
        return compile_mission(path)
    with mock.patch.object(shortest, "corner_candidate", return_value=None):
        return compile_mission(path)


def _length_until_last_goal(result: CompileResult, goals: list[str]) -> float:
    """The trace's polyline until it has entered every goal in turn (shapely)."""
    mission = result.compilation.get(MISSION)
    shapes = {r.name: shapely.Polygon(r.polygon) for r in mission.regions}
    points = np.asarray(result.artifacts["trace.json"]["points"], dtype=np.float64)[:, 1:]
    pending = list(goals)
    for index, point in enumerate(points):
        if pending and shapes[pending[0]].covers(shapely.Point(point)):
            pending.pop(0)
        if not pending:
            return float(np.hypot(*np.diff(points[: index + 1], axis=0).T).sum())
    raise AssertionError("the trace never met the task")


def test_reach_avoid_keeps_a_shorter_trajectory_on_a_mesh_cut_at_its_corners() -> None:
    """The reach-avoid spec bends round its obstacles' corners on the way to the dock and
    home: the candidate cuts rings there, is kept, its trace is shorter until the task is
    met than without the candidate, it verifies, and it is not slower than the midpoint plan
    (the plan before any re-plan)."""
    result = _compiled("reach-avoid.yaml", rings=True)
    plain = _compiled("reach-avoid.yaml", rings=False)
    stats = result.compilation.get(WITNESS).stats
    assert "ring_time" in stats
    written = result.artifacts["abstraction.json"]
    assert written["stats"]["rings_at_corners"] > 0
    assert "rings_at_corners" not in plain.artifacts["abstraction.json"]["stats"]
    goals = ["dock", "home"]
    assert _length_until_last_goal(result, goals) < _length_until_last_goal(plain, goals)
    assert result.summary()["verdict"]["satisfied"] is True
    with mock.patch.object(shortest, "plan_shortest", side_effect=lambda _m, p: p):
        first = compile_mission(str(ROOT / "specs" / "reach-avoid.yaml"))
    mission = result.compilation.get(MISSION)
    midpoint_time = measure(mission, _planned(first)).exact_time
    assert stats["ring_time"] <= midpoint_time


def _planned(result: CompileResult) -> Planned:
    from tlmpc.pipeline.stages import ABSTRACTION, AUTOMATON

    return Planned(
        abstraction=result.compilation.get(ABSTRACTION),
        automaton=result.compilation.get(AUTOMATON),
        witness=result.compilation.get(WITNESS),
    )


def _turns(guides: list[Any]) -> list[float]:
    """The sine of the turn between consecutive pieces (a brute-force reading)."""
    sines = []
    for first, second in itertools.pairwise(guides):
        ax, ay = first.exit[0] - first.entry[0], first.exit[1] - first.entry[1]
        bx, by = second.exit[0] - second.entry[0], second.exit[1] - second.entry[1]
        sines.append((ax * by - ay * bx) / (math.hypot(ax, ay) * math.hypot(bx, by)))
    return sines


@pytest.mark.parametrize("spec", ["example1.yaml", "reach-avoid.yaml", "example7.yaml"])
def test_every_corner_is_an_end_of_a_portal_the_path_turns_across(spec: str) -> None:
    """Each vertex named is an end of the exit edge of a step after which the path turns by
    more than TURN, on the inside of the turn; and each turn by more than TURN that passes
    within NEAR of its inner end names it."""
    result = _compiled(spec, rings=False)
    planned = _planned(result)
    mission = result.compilation.get(MISSION)
    mesh = planned.abstraction
    steps, loop_start = plan_steps(mesh, planned.witness)
    bends = corners.plan_bends(mission, planned)
    assert bends is not None
    guides, found = bends.guides, list(bends.corners)
    expected = []
    moving = [k for k, s in enumerate(steps) if s.exit_edge is not None]
    sines = _turns([guides[k] for k in range(len(steps))])
    for k in moving:
        edge = steps[k].exit_edge
        piece = guides[k]
        if k + 1 >= len(steps) or abs(sines[k]) <= corners.TURN:
            continue
        assert edge is not None
        assert piece is not None
        left, right = (
            mesh.triangles[steps[k].triangle][(edge + 2) % 3],
            mesh.triangles[steps[k].triangle][(edge + 1) % 3],
        )
        inner, outer = (left, right) if sines[k] > 0 else (right, left)
        width = math.dist(mesh.vertices[inner], mesh.vertices[outer])
        if math.dist(piece.exit, mesh.vertices[inner]) <= corners.NEAR * width:
            expected.append(int(inner))
    if loop_start is None:
        assert found == expected
    else:
        assert found[: len(expected)] == expected


class _Fake:
    """Stands in for a plan: _run is patched to read its (time, trajectory length)."""

    def __init__(self, time: float, travelled: float) -> None:
        self.run = (time, travelled)


@pytest.mark.parametrize(
    ("first", "kept", "candidate", "path", "replaced"),
    [
        # shorter trajectory, not slower than the midpoint plan: kept
        ((10.0, 20.0), None, (10.0, 19.0), 9.0, True),
        # ... a little slower than the kept plan, but not than the midpoint plan: kept
        ((10.0, 20.0), (9.0, 19.5), (9.5, 19.0), 9.0, True),
        # slower than the midpoint plan
        ((10.0, 20.0), None, (10.01, 18.0), 9.0, False),
        # its trajectory not shorter by more than MIN_GAIN
        ((10.0, 20.0), None, (9.0, 20.0 * (1 - shortest.MIN_GAIN)), 9.0, False),
        # its path longer than the midpoint plan's
        ((10.0, 20.0), None, (9.0, 18.0), 10.5, False),
    ],
)
def test_a_plan_cut_at_corners_is_kept_on_its_trajectory(
    first: tuple[float, float],
    kept: tuple[float, float] | None,
    candidate: tuple[float, float],
    path: float,
    replaced: bool,
) -> None:
    """The rule of _Kept.offer_trajectory, its runs stood in for: a shorter trajectory (by
    more than MIN_GAIN), a path no longer and an exact time no longer than the midpoint
    plan's."""
    runs: dict[int, tuple[float, float]] = {}

    def run(_mission: Any, planned: Any, *, verified: bool) -> tuple[float, float]:
        del verified
        return runs[id(planned)]

    midpoint = _Fake(*first)
    holder = shortest._Kept(mock.Mock(), midpoint, 10.0)  # type: ignore[arg-type]
    runs[id(midpoint)] = midpoint.run
    if kept is not None:
        better = _Fake(*kept)
        runs[id(better)] = better.run
        with mock.patch.object(shortest, "_run", run):
            holder._measure_kept()
            holder._keep(better, 9.5, *kept)  # type: ignore[arg-type]
    offered = _Fake(*candidate)
    runs[id(offered)] = offered.run
    pulled = shortest.Pulled(length=path, moves={})
    with mock.patch.object(shortest, "_run", run):
        time = holder.offer_trajectory(offered, pulled)  # type: ignore[arg-type]
    assert (holder.planned is cast(Any, offered)) is replaced
    if path <= 10.0:
        assert time == candidate[0]


def _inradius(mesh: Any, t: int) -> float:
    shape = shapely.Polygon(mesh.corners(t).tolist())
    return float(2 * shape.area / shape.length)


@pytest.mark.parametrize(
    ("spec", "cuts"),
    [("example1.yaml", False), ("example7.yaml", False), ("reach-avoid.yaml", True)],
)
def test_ring_counts_keep_the_clearance_and_the_plans_smallest_triangle(
    spec: str, cuts: bool
) -> None:
    """For every fifth vertex of the mesh: the rings counted leave every triangle about it an
    inradius (shapely: twice the area over the perimeter) of at least the floor, and one more
    ring would not (unless RINGS are cut); about a corner on a region's own boundary (within
    a millionth of the extent of a region's outline), at most as many as keep the label
    clearance at LABEL_INSET of its shortest edge."""
    result = _compiled(spec, rings=False)
    mission = result.compilation.get(MISSION)
    planned = _planned(result)
    mesh = planned.abstraction
    route = {*planned.witness.prefix, *planned.witness.cycle}
    floor = min(_inradius(mesh, t) for t in route)
    clearance = label_clearance(mission.robot.max_speed)
    chosen = list(range(0, len(mesh.vertices), 5))
    counts = corners.ring_counts(mesh, chosen, clearance, floor)
    unfloored = corners.ring_counts(mesh, chosen, clearance, 0.0)
    outlines = shapely.union_all([shapely.Polygon(r.polygon).boundary for r in mission.regions])
    extent = float(np.ptp(mesh.vertices, axis=0).max())
    start = mission.robot.start
    cut_some = 0
    for v in chosen:
        around = [t for t in range(mesh.num_triangles) if v in mesh.triangles[t].tolist()]
        shortest_edge = min(
            math.dist(mesh.vertices[v], mesh.vertices[w])
            for t in around
            for w in mesh.triangles[t].tolist()
            if w != v
        )
        labels = {int(mesh.letter_of[t]) for t in around}
        label_most = corners.RINGS
        if len(labels) > 1 and outlines.distance(shapely.Point(mesh.vertices[v])) <= 1e-6 * extent:
            fits = [
                k
                for k in range(1, corners.RINGS + 1)
                if RING_FRACTION**k * shortest_edge * LABEL_INSET >= clearance
            ]
            label_most = max(fits, default=0)
        count = counts.get(v, 0)
        assert count <= label_most
        assert unfloored.get(v, 0) == label_most  # without a floor, the clearance decides

        def smallest_about(k: int, v: int = v) -> float:
            refined, _ = ring_corners(mesh, {v: k}, start)
            if refined is mesh:
                return math.inf
            return min(
                _inradius(refined, t)
                for t in range(refined.num_triangles)
                if v in refined.triangles[t].tolist() or t >= mesh.num_triangles
            )

        if count > 0:
            cut_some += 1
            assert smallest_about(count) >= floor * (1 - 1e-9)
        if count < min(label_most, corners.RINGS):
            assert smallest_about(count + 1) < floor * (1 + 1e-9)
    assert (cut_some > 0) is cuts


def test_a_laps_trajectory_length_weighs_the_lap_by_beta() -> None:
    """step_times' trajectory length of a lasso: the trace's length (shapely) until the
    prefix's last crossing plus beta times the length of the second pass of the cycle."""
    import yaml

    from tlmpc.control import synthesize
    from tlmpc.pipeline.mintime import step_times
    from tlmpc.simulate import simulate

    document = yaml.safe_load((ROOT / "specs" / "patrol.yaml").read_text())
    document["options"] = {"cost": "length", "beta": 0.5}
    result = compile_mission("patrol.yaml", text=yaml.safe_dump(document), until="plan")
    c = result.compilation
    mission, witness = c.get(MISSION), c.get(WITNESS)
    mesh = _planned(result).abstraction
    controllers = synthesize(mesh, witness, mission.robot)
    trace = simulate(mesh, controllers, mission)
    found = step_times(mesh, controllers, trace, witness.beta)
    points = np.asarray(trace.points)
    steps = len(controllers.steps)
    loop = controllers.loop_start
    assert loop is not None
    assert loop > 0

    def along(first: int, last: int) -> float:
        return float(shapely.LineString(points[first : last + 1]).length) if last > first else 0.0

    crossings = trace.crossings  # one per moving step: the steps, then the cycle again
    prefix = along(0, crossings[loop - 1])
    lap = along(crossings[steps - 1], crossings[-1])
    assert found.exact_length == pytest.approx(prefix + 0.5 * lap, rel=1e-9)


def test_example_7_keeps_a_shorter_trajectory_on_its_corridor_meshed_finer() -> None:
    """Example 7's mesh is a few large triangles: the corridor candidate meshes the kept
    plan's corridor finer, is kept, its trace is shorter until the task is met than with the
    ring candidate alone, it verifies, and it is not slower than the midpoint plan."""
    path = str(ROOT / "specs" / "example7.yaml")
    result = compile_mission(path)
    original = corners.corner_candidate

    def rings_only(
        mission: Any, planned: Planned, bends: Any, *, refine: bool = False
    ) -> Planned | None:
        return None if refine else original(mission, planned, bends)

    with mock.patch.object(shortest, "corner_candidate", side_effect=rings_only):
        plain = compile_mission(path)
    stats = result.compilation.get(WITNESS).stats
    assert "corridor_time" in stats
    assert result.artifacts["abstraction.json"]["stats"]["corridor_refinements"] > 0
    assert "corridor_refinements" not in plain.artifacts["abstraction.json"]["stats"]

    def goals(compiled: CompileResult) -> list[str]:
        # r2, then r1, then r3, r4 and r5 in the order the trace first enters them
        mission = compiled.compilation.get(MISSION)
        shapes = {r.name: shapely.Polygon(r.polygon) for r in mission.regions}
        points = np.asarray(compiled.artifacts["trace.json"]["points"], dtype=np.float64)
        entered = {
            name: next(
                k for k, p in enumerate(points[:, 1:]) if shapes[name].covers(shapely.Point(p))
            )
            for name in ("r3", "r4", "r5")
        }
        return ["r2", "r1", *sorted(entered, key=entered.__getitem__)]

    assert _length_until_last_goal(result, goals(result)) < 0.98 * _length_until_last_goal(
        plain, goals(plain)
    )
    assert result.summary()["verdict"]["satisfied"] is True
    with mock.patch.object(shortest, "plan_shortest", side_effect=lambda _m, p: p):
        first = compile_mission(path)
    mission = result.compilation.get(MISSION)
    assert stats["corridor_time"] <= measure(mission, _planned(first)).exact_time
