"""The runtime executor: point location, task tracking, plan steps, recovery, unicycle.

Oracles are independent of the executor: shapely for point location and for obstacles, a
finite-difference derivative of the exact unicycle flow for the feedback linearisation, and
the verifier (which shares no code with planning or control) for every claim that a run
satisfies its task.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import tlmpc
from tlmpc.runtime import Executor, run_closed_loop
from tlmpc.runtime.closed_loop import default_dt
from tlmpc.runtime.disturbance import adversarial_direction
from tlmpc.runtime.unicycle import unicycle_command, unicycle_flow, unicycle_inflation
from tlmpc.verify import verify_document

FloatArray = np.ndarray[Any, np.dtype[np.float64]]


def _mission(task: str, **robot: Any) -> dict[str, Any]:
    """A 10 x 4 corridor: ``a`` up in the middle, ``b`` low on the right, start low left."""
    return {
        "version": 1,
        "name": "corridor",
        "workspace": {"boundary": {"rect": [0, 0, 10, 4]}},
        "regions": {"a": {"rect": [4, 3, 6, 4]}, "b": {"rect": [8.5, 0, 10, 1]}},
        "robot": {"start": [1, 1], "max_speed": 1.0, **robot},
        "task": [task],
        # the recoveries below are set up on this corridor's plain mesh (goals not cored)
        "options": {"goal_depth": 0},
    }


_COMPILED: dict[str, tlmpc.Compiled] = {}


def _compiled(task: str, **robot: Any) -> tlmpc.Compiled:
    key = repr((task, sorted(robot.items())))
    if key not in _COMPILED:
        _COMPILED[key] = tlmpc.compile(_mission(task, **robot))
    return _COMPILED[key]


Kick = Callable[[float, FloatArray, Executor], FloatArray]


def _kick(at: float, dt: float, target: FloatArray) -> Kick:
    """A disturbance that moves the robot to ``target`` in the one sample after ``at``
    (a push far above any bound), and is zero otherwise."""

    def push(t: float, point: FloatArray, executor: Executor) -> FloatArray:
        if at <= t < at + dt:
            velocity: FloatArray = (target - point) / dt - executor.velocity(point)
            return velocity
        return np.zeros(2)

    return push


def _holes_avoided(document: dict[str, Any] | Any) -> bool:
    """Shapely: the reference point's polyline stays in the workspace, outside every hole."""
    points = [(x, y) for _, x, y in document["points"]]
    path = shapely.LineString(points) if len(points) > 1 else shapely.Point(points[0])
    outer = shapely.Polygon(document["workspace"]["boundary"])
    holes = [shapely.Polygon(h) for h in document["workspace"].get("holes", [])]
    inside = outer.buffer(1e-9).covers(path)
    return inside and not any(path.intersection(h).length > 1e-9 for h in holes)


# --- point location ------------------------------------------------------------------------


@settings(max_examples=max(10, settings().max_examples // 4))
@given(st.floats(0.0, 10.0), st.floats(0.0, 4.0))
def test_every_point_is_located_in_a_triangle_shapely_agrees_holds_it(x: float, y: float) -> None:
    executor = tlmpc.executor(_compiled("visit a then b"))
    triangle = executor.locator.locate(np.array([x, y]))
    assert triangle is not None
    polygon = shapely.Polygon(executor.abstraction.corners(triangle).tolist())
    assert polygon.buffer(1e-7).covers(shapely.Point(x, y))


@settings(max_examples=max(10, settings().max_examples // 4))
@given(st.floats(0.01, 9.99), st.floats(0.01, 3.99), st.floats(0.01, 9.99), st.floats(0.01, 3.99))
def test_a_walk_enters_exactly_the_triangles_shapely_says_the_segment_crosses(
    x0: float, y0: float, x1: float, y1: float
) -> None:
    executor = tlmpc.executor(_compiled("visit a then b"))
    start, end = np.array([x0, y0]), np.array([x1, y1])
    first = executor.locator.locate(start)
    assert first is not None
    walked = executor.locator.walk(first, start, end)
    assert walked is not None
    assert executor.locator.contains(walked[-1] if walked else first, end)
    segment = shapely.LineString([(x0, y0), (x1, y1)])
    crossed = {
        t
        for t in range(executor.abstraction.num_triangles)
        if shapely.Polygon(executor.abstraction.corners(t).tolist()).intersection(segment).length
        > 1e-6
    }
    # Every triangle the segment runs through for a positive length is walked, and the walk
    # enters nothing the segment does not touch; consecutive ones share an edge.
    assert crossed <= {first, *walked}
    for t in walked:
        poly = shapely.Polygon(executor.abstraction.corners(t).tolist())
        assert poly.distance(segment) < 1e-9
    for a, b in zip([first, *walked], walked, strict=False):
        assert b in executor.abstraction.neighbors[a]


# --- plan following and recovery -----------------------------------------------------------


def test_an_undisturbed_run_follows_the_plan_without_recovering() -> None:
    executor = tlmpc.executor(_compiled("visit a then b"))
    run = run_closed_loop(executor, lambda t, p, e: np.zeros(2), bound=0.0)
    assert run.completed
    assert run.progress.status == "following"
    assert run.recoveries == ()
    assert run.progress.phase == "stay"
    assert run.progress.visits["a"] >= 1
    assert run.progress.visits["b"] >= 1
    assert verify_document(run.trace).satisfied


@pytest.mark.parametrize(
    ("b", "ltl", "crossings"),
    [
        ([2, 1, 3, 2], "F (a & b)", "across"),  # b shares a's right edge: met on the edge
        ([2, 2, 3, 3], "F (a & b)", "corner"),  # b touches a's corner only: a vertex passage
        ([2, 1, 3, 2], "F a & F b & G !(a & b)", "around"),  # never on the shared edge
    ],
)
def test_the_executor_runs_closed_convention_plans(b: list[int], ltl: str, crossings: str) -> None:
    """Under the closed convention every handover instant is read with its own letter (the
    plan's states are a run over them), so the executor follows the compiled plan without
    re-planning, and the verifier, under the same convention, accepts the run."""
    mission = {
        "version": 1,
        "name": f"closed-{crossings}",
        "workspace": {"boundary": {"rect": [0, 0, 4, 4]}},
        "regions": {"a": {"rect": [1, 1, 2, 2]}, "b": {"rect": b}},
        "robot": {"start": [0.5, 0.5], "max_speed": 1.0},
        "ltl": ltl,
        "options": {"boundary": "closed"},
    }
    executor = tlmpc.executor(tlmpc.compile(mission))
    run = run_closed_loop(executor, lambda t, p, e: np.zeros(2), bound=0.0)
    assert run.completed
    assert run.progress.status == "following"
    assert run.recoveries == ()
    verdict = verify_document(run.trace)
    assert verdict.satisfied


def test_a_push_past_the_goal_replans_from_the_tracked_automaton_state() -> None:
    """Pushed from the start onto the plan after ``a`` without having visited ``a``: the
    plan's step there assumes ``a`` was seen, so re-entering would skip ``a``.  The executor
    must re-plan (back to ``a``), and the run must still satisfy the task."""
    compiled = _compiled("visit a then b")
    executor = tlmpc.executor(compiled)
    start = shapely.Point(executor.mission.robot.start)
    region_a = shapely.Polygon(executor.mission.region("a").polygon)
    steps = executor.plan.steps
    first_a = next(i for i, s in enumerate(steps) if "a" in executor.abstraction.labels(s.triangle))
    before = {s.triangle for s in steps[: first_a + 1]}
    target = None
    for step in steps[first_a + 1 :]:
        corners = executor.abstraction.corners(step.triangle)
        center = corners.mean(axis=0)
        if (
            step.triangle not in before
            and not executor.abstraction.labels(step.triangle)
            and not shapely.LineString([start, tuple(center)]).intersects(region_a)
        ):
            target = center
            break
    assert target is not None, "the corridor has a plan triangle past a reachable around a"
    dt = default_dt(executor.plan, 1.0)
    run = run_closed_loop(executor, _kick(0.0, dt, target), bound=0.0, dt=dt)
    kinds = [r.kind for r in run.recoveries]
    # (the push crosses several plan triangles past ``a`` in one sample: one re-plan each)
    assert kinds
    assert set(kinds) == {"replan"}
    assert run.progress.visits["a"] >= 1
    verdict = verify_document(run.trace)
    assert verdict.satisfied, verdict.violations


def test_a_robot_found_past_the_goal_after_losing_track_replans_instead_of_reentering() -> None:
    """Localisation lost (the pose outside the map), then found on a plan triangle that the
    plan reaches only after ``a``: the robot has not seen ``a``, so re-entering there would
    skip it; the executor must re-plan, and the new plan must go through ``a``."""
    executor = tlmpc.executor(_compiled("visit a then b"))
    labels = executor.abstraction.labels
    steps = executor.plan.steps
    first_a = next(i for i, s in enumerate(steps) if "a" in labels(s.triangle))
    before = {s.triangle for s in steps[: first_a + 1]}
    after = next(
        s for s in steps[first_a + 1 :] if s.triangle not in before and not labels(s.triangle)
    )
    executor.command(executor.mission.robot.start, 0.0)
    executor.command((-5.0, -5.0), 0.1)
    lost = executor.progress
    assert lost.status == "outside"
    executor.command(tuple(executor.abstraction.corners(after.triangle).mean(axis=0)), 0.2)
    assert [r.kind for r in executor.recoveries] == ["replan"]
    found = executor.progress
    assert found.status == "following"
    new_labels = [labels(s.triangle) for s in executor.plan.steps]
    goal_a = next(i for i, names in enumerate(new_labels) if "a" in names)
    assert any("b" in names for names in new_labels[goal_a:])


def test_a_replan_starts_from_the_goals_already_reached() -> None:
    """After ``a`` was reached, a robot found again back near the start re-plans from the
    tracked automaton state: straight to ``b``, never back to ``a``."""
    executor = tlmpc.executor(_compiled("visit a then b"))
    labels = executor.abstraction.labels
    executor.command(executor.mission.robot.start, 0.0)
    executor.command((5.0, 3.5), 1.0)  # inside a
    assert executor.progress.visits["a"] == 1
    executor.command((-5.0, -5.0), 2.0)  # localisation lost
    executor.command((0.5, 0.3), 3.0)  # found again in the bottom-left corner
    assert executor.recoveries[-1].kind == "replan"
    ahead = [labels(s.triangle) for s in executor.plan.steps[executor.progress.step :]]
    assert not any("a" in names for names in ahead)
    assert "b" in ahead[-1]


def test_a_push_back_along_the_cycle_reenters_the_plan() -> None:
    """GF a & GF b: pushed back onto an earlier triangle of the cycle, the executor re-enters
    there (every cycle state is consistent with any history that reached the cycle)."""
    compiled = _compiled("visit a and b infinitely often")
    executor = tlmpc.executor(compiled)
    plan = executor.plan
    assert plan.loop_start is not None
    dt = default_dt(plan, 1.0)
    # Let the robot reach the middle of its first lap, then push it back to the lap's start.
    probe = run_closed_loop(tlmpc.executor(compiled), lambda t, p, e: np.zeros(2), bound=0.0)
    points = probe.trace["points"]  # the prefix, then one lap from points[loop_start]
    lap_start = points[probe.trace["loop_start"]][0]
    middle_time = lap_start + 0.5 * (points[-1][0] - lap_start)
    target = executor.abstraction.corners(plan.steps[plan.loop_start].triangle).mean(axis=0)
    run = run_closed_loop(executor, _kick(middle_time, dt, target), bound=0.0, dt=dt, cycles=2)
    assert run.progress.reentries + run.progress.replans >= 1
    assert run.completed
    verdict = verify_document(run.trace)
    assert verdict.satisfied, verdict.violations


def test_a_run_pushed_into_a_forbidden_region_is_reported_violated_and_stopped() -> None:
    compiled = _compiled("visit b while avoiding a")
    executor = tlmpc.executor(compiled)
    dt = default_dt(executor.plan, 1.0)
    run = run_closed_loop(executor, _kick(0.0, dt, np.array([5.0, 3.5])), bound=0.0, dt=dt)
    assert run.progress.status == "violated"
    assert run.recoveries[-1].kind == "violated"
    assert run.progress.automaton_states == ()
    assert executor.command((5.0, 3.5), 1.0) == (0.0, 0.0)
    assert not verify_document(run.trace).satisfied  # the verifier agrees


# --- the disturbance models ----------------------------------------------------------------


def test_the_adversary_pushes_out_of_the_nearest_guarded_facet_or_against_the_exit() -> None:
    executor = tlmpc.executor(_compiled("visit a then b"))
    executor.command(executor.mission.robot.start, 0.0)
    rng = np.random.default_rng(7)
    for step in executor.plan.steps:
        if step.exit_edge is None:
            continue
        executor._step = step.step  # inspect every step's adversary
        vertices = step.vertices
        exit_a = vertices[(step.exit_edge + 1) % 3]
        exit_b = vertices[(step.exit_edge + 2) % 3]
        exit_normal = np.array([exit_b[1] - exit_a[1], exit_a[0] - exit_b[0]])
        exit_normal /= np.linalg.norm(exit_normal)
        for weights in rng.dirichlet(np.ones(3), size=8):
            point = weights @ vertices
            direction = adversarial_direction(executor, point)
            assert abs(float(np.linalg.norm(direction)) - 1.0) < 1e-12
            facet_distance = {
                i: shapely.LineString(
                    [vertices[(i + 1) % 3].tolist(), vertices[(i + 2) % 3].tolist()]
                ).distance(shapely.Point(point.tolist()))
                for i in range(3)
            }
            guarded = min(
                (i for i in range(3) if i != step.exit_edge), key=lambda i: facet_distance[i]
            )
            if facet_distance[guarded] < facet_distance[step.exit_edge] - 1e-9:
                # Straight out through that facet: perpendicular to it, away from the vertex
                # opposite it.
                a, b = vertices[(guarded + 1) % 3], vertices[(guarded + 2) % 3]
                assert abs(float(direction @ (b - a))) < 1e-9
                assert float(direction @ (vertices[guarded] - a)) < 0
            elif facet_distance[step.exit_edge] < facet_distance[guarded] - 1e-9:
                assert np.allclose(direction, -exit_normal)


def test_an_adversarial_push_slows_the_plan_down() -> None:
    compiled = _compiled("visit a then b", disturbance=0.1)
    calm = run_closed_loop(tlmpc.executor(compiled), lambda t, p, e: np.zeros(2), bound=0.0)
    from tlmpc.runtime import adversarial_disturbance

    pushed = run_closed_loop(
        tlmpc.executor(compiled), adversarial_disturbance(0.1), bound=0.1, dt=calm.dt
    )

    def arrival(run: Any) -> float:  # time the stay triangle is first reached
        last = run.trace["points"][-1]
        return float(last[0])

    assert verify_document(pushed.trace).satisfied
    assert arrival(pushed) > arrival(calm)


# --- unicycle ------------------------------------------------------------------------------


@settings(max_examples=max(10, settings().max_examples // 4))
@given(
    st.floats(-math.pi, math.pi),
    st.floats(-1.0, 1.0),
    st.floats(-1.0, 1.0),
    st.floats(0.05, 2.0),
)
def test_feedback_linearisation_moves_the_point_ahead_with_the_commanded_velocity(
    theta: float, ux: float, uy: float, offset: float
) -> None:
    """Oracle: a central finite difference of the exact unicycle flow of (v, omega)."""
    u = np.array([ux, uy])
    v, omega = unicycle_command(theta, u, offset)
    h = 1e-6

    def ahead(dt: float) -> FloatArray:
        x, y, th = unicycle_flow((0.0, 0.0, theta), v, omega, dt)
        return np.array([x + offset * math.cos(th), y + offset * math.sin(th)])

    derivative = (ahead(h) - ahead(-h)) / (2 * h)
    assert np.allclose(derivative, u, atol=1e-6)
    assert abs(v) <= math.hypot(ux, uy) + 1e-12
    assert abs(omega) <= math.hypot(ux, uy) / offset + 1e-12


def test_unicycle_inflation_is_the_offset_for_a_unicycle_and_zero_for_a_point() -> None:
    unicycle = tlmpc.executor(_compiled("visit a then b", model="unicycle", offset=0.3))
    point = tlmpc.executor(_compiled("visit a then b"))
    assert unicycle_inflation(unicycle.mission.robot) == 0.3
    assert unicycle_inflation(point.mission.robot) == 0.0


@pytest.mark.parametrize("heading", [0.0, math.pi / 2, math.pi, -2.5])
def test_a_unicycle_reaches_its_goals_from_any_heading(heading: float) -> None:
    executor = tlmpc.executor(_compiled("visit a then b", model="unicycle", offset=0.2))
    run = run_closed_loop(executor, lambda t, p, e: np.zeros(2), bound=0.0, heading=heading)
    assert run.completed
    assert run.trace["points"][0][1:] == pytest.approx(
        [1.0, 1.0]
    )  # the trace is the reference point's
    verdict = verify_document(run.trace)
    assert verdict.satisfied, verdict.violations
    assert _holes_avoided(run.trace)


def test_the_executor_needs_the_control_stage() -> None:
    partial = tlmpc.compile(_mission("visit a then b"), until="plan")
    with pytest.raises(tlmpc.UsageError) as caught:
        tlmpc.executor(partial)
    assert caught.value.diagnostics[0].code == "R020"


@pytest.mark.parametrize(
    ("pose", "robot"),
    [
        ((1.0, 1.0, 0.0), {}),
        ((1.0,), {}),
        ((float("nan"), 1.0), {}),
        ((1.0, 1.0), {"model": "unicycle", "offset": 0.2}),
        (None, {}),  # not numbers at all: still R023, not Python's own errors
        (("a", "b"), {}),
        ((10**400, 1), {}),
    ],
)
def test_a_malformed_pose_is_R023(pose: Any, robot: dict[str, Any]) -> None:
    executor = tlmpc.executor(_compiled("visit a then b", **robot))
    with pytest.raises(tlmpc.UsageError) as caught:
        executor.command(pose, 0.0)
    assert caught.value.diagnostics[0].code == "R023"


@pytest.mark.parametrize("t", [None, "now", 10**400])
def test_a_malformed_time_is_R023(t: Any) -> None:
    executor = tlmpc.executor(_compiled("visit a then b"))
    with pytest.raises(tlmpc.UsageError) as caught:
        executor.command((1.0, 1.0), t)
    assert caught.value.diagnostics[0].code == "R023"
