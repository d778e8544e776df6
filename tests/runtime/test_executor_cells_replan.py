"""A run planned on convex cells is re-planned on convex cells when pushed off its plan.

A T of three rooms (left, middle, the goal ``a`` on the right, and a narrow room above the
middle) under a disturbance of 0.6 x max_speed: no triangle carries it (a triangle's corners
push at most sin(30 degrees) = 0.5), so the mission compiles on convex cells only. A push
throws the robot into the top room, which no cell step of the plan covers: the executor must
re-plan there, from the robot's cell and tracked automaton states, and the re-plan must be
on cells again (on triangles alone there is none). The run is then driven by the declared
disturbance at its full bound, adversarial or random; the trace is judged by the verifier's
own evaluator and, independently, by shapely: every sample lies in the workspace and the run
ends inside ``a``; no recovery happens after the push.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
import pytest
import shapely

import tlmpc
from tlmpc.base.errors import TlmpcError
from tlmpc.runtime import Executor, make_disturbance, run_closed_loop
from tlmpc.runtime.closed_loop import default_dt
from tlmpc.verify import verify_document

FloatArray = np.ndarray[Any, np.dtype[np.float64]]

RATIO = 0.6
T_SHAPE = [(0, 0), (9, 0), (9, 3), (5, 3), (5, 6), (4, 6), (4, 3), (0, 3)]
GOAL = (6.0, 0.0, 9.0, 3.0)
#: Where the push throws the robot: over the middle room, then up into the top room.
WAYPOINT = np.array([4.5, 1.5])
TOP = np.array([4.5, 5.0])


def _mission(ratio: float = RATIO) -> dict[str, Any]:
    return {
        "version": 1,
        "workspace": {"boundary": [list(p) for p in T_SHAPE]},
        "regions": {"a": {"rect": list(GOAL)}},
        "robot": {"start": [1.5, 1.5], "max_speed": 1.0, "disturbance": ratio},
        "options": {"min_angle": None, "goal_depth": 0, "margin": 0},
        "ltl": "F G a",
    }


@pytest.fixture(scope="module")
def compiled() -> Any:
    return tlmpc.compile(_mission())


def test_the_mission_compiles_on_cells_only(compiled: Any) -> None:
    steps = compiled.artifacts["controllers.json"]["steps"]
    assert steps
    assert all(s.get("kind") == "cell" for s in steps)
    top = shapely.box(4.0, 3.0, 5.0, 6.0)
    executor = tlmpc.executor(compiled)
    for step in executor.plan.steps:
        assert step.cell is not None
        for triangle in step.cell.triangles:
            centroid = executor.abstraction.corners(triangle).mean(axis=0)
            assert not top.contains(shapely.Point(centroid)), "the plan avoids the top room"


@pytest.mark.parametrize("model", ["adversarial", "random"])
def test_a_push_into_a_room_off_the_plan_replans_on_cells(
    compiled: Any, model: Literal["adversarial", "random"]
) -> None:
    executor = tlmpc.executor(compiled)
    bound = RATIO * executor.mission.robot.max_speed
    dt = default_dt(executor.plan, executor.mission.robot.max_speed + bound)
    declared = make_disturbance(model, bound, 3, 10 * dt)

    def push(t: float, point: FloatArray, running: Executor) -> FloatArray:
        if t < 2.5 * dt:  # two samples: over the middle room, then into the top room
            goal = WAYPOINT if t < 0.5 * dt else TOP
            thrown: FloatArray = (goal - point) / dt - running.velocity(point)
            return thrown
        within: FloatArray = declared(t, point, running)
        return within

    run = run_closed_loop(executor, push, bound=bound, dt=dt)
    kinds = [r.kind for r in run.recoveries]
    assert "replan" in kinds, run.recoveries
    assert "no_plan" not in kinds, run.recoveries
    # every recovery is the push's: under the declared bound the cell fields hold
    assert all(r.time <= 2.5 * dt for r in run.recoveries), run.recoveries
    assert run.progress.status == "following"
    assert run.completed
    assert all(step.kind == "cell" for step in executor.plan.steps)
    top = shapely.box(4.0, 3.0, 5.0, 6.0)
    first = executor.plan.steps[0]
    assert first.cell is not None
    assert any(
        top.contains(shapely.Point(executor.abstraction.corners(t).mean(axis=0)))
        for t in first.cell.triangles
    ), "the re-plan starts in the robot's cell, in the top room"
    verdict = verify_document(run.trace)
    assert verdict.satisfied, [v.message for v in verdict.violations]
    points = [shapely.Point(x, y) for _, x, y in run.trace["points"]]
    free = shapely.Polygon(T_SHAPE).buffer(1e-9)
    assert all(free.contains(p) for p in points)
    assert shapely.box(*GOAL).contains(points[-1])


def test_the_mission_has_no_plan_on_triangles() -> None:
    """Every rung before the cells fails: compile refuses it with the cells' rung switched
    off (the triangles' bound is sin 30 degrees at best)."""
    from unittest import mock

    from tlmpc.planning import mission

    with (
        mock.patch.object(mission, "_on_cells", return_value=None),
        mock.patch.object(mission, "_on_lines", return_value=(None, None)),
        pytest.raises(TlmpcError) as caught,
    ):
        tlmpc.compile(_mission())
    assert {d.code for d in caught.value.diagnostics} == {"C032"}
