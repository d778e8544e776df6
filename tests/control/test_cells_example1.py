"""Example 1 at robot.disturbance = 0.5 x max_speed, on convex cells.

No triangle rejects half of max_speed in every direction (a triangle has a corner of at most
60 degrees, and a kept corner of angle a pushes at most sin(a / 2)): Example 1 was refused from
0.383. On the convex cells' own mesh (every side extended across the workspace) it compiles;
the trace verifies (``tlmpc verify`` exits 0); the runtime executor's closed loop under
adversarial and random pushes of the full bound verifies with the independent verifier; and
an independent adversarial Euler loop (tests/oracles/cell_adversary.py) run on every cell
step of the plan, from every corner of the cell (a hair inside) and its centroid, leaves
each move's cell only through its interface and never leaves a stay's. A push off the plan
(into the right-hand side, between p4 and p3) is re-planned on cells from where it lands,
and the run goes on to verify under the adversarial disturbance at the full bound.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pytest
import shapely
import yaml
from cell_adversary import CellLoop

import tlmpc
from tlmpc.runtime import Executor, make_disturbance, run_closed_loop
from tlmpc.runtime.closed_loop import default_dt
from tlmpc.verify import verify_document

ROOT = Path(__file__).resolve().parents[2]
RATIO = 0.5
#: The longest an adversarial run is followed (seconds).
CAP = 60.0


def _mission() -> dict[str, Any]:
    doc: dict[str, Any] = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    doc["robot"]["disturbance"] = RATIO * float(doc["robot"]["max_speed"])
    return doc


@pytest.fixture(scope="module")
def compiled() -> Any:
    return tlmpc.compile(_mission())


def test_compiles_on_cells_and_verifies(compiled: Any, tmp_path: Path) -> None:
    steps = compiled.artifacts["controllers.json"]["steps"]
    assert all(s.get("kind") == "cell" for s in steps)
    assert compiled.artifacts["verdict.json"]["verdict"] == "satisfied"
    compiled.write(tmp_path / "out")
    done = subprocess.run(
        [sys.executable, "-m", "tlmpc", "verify", str(tmp_path / "out" / "trace.json")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.slow
@pytest.mark.parametrize("model", ["adversarial", "random"])
def test_closed_loop_runs_at_the_full_bound_verify(
    compiled: Any, model: Literal["random", "adversarial"]
) -> None:
    executor = tlmpc.executor(compiled)
    bound = RATIO * executor.mission.robot.max_speed
    hold = 10 * default_dt(executor.plan, executor.mission.robot.max_speed + bound)
    run = run_closed_loop(executor, make_disturbance(model, bound, 0, hold), bound=bound)
    verdict = verify_document(run.trace)
    assert verdict.satisfied, [v.message for v in verdict.violations]
    assert run.completed


@pytest.mark.slow
def test_every_cell_step_resists_the_adversary(compiled: Any) -> None:
    d = RATIO
    for step in compiled.artifacts["controllers.json"]["steps"]:
        loop = CellLoop(step)
        centre = np.asarray(loop.polygon.centroid.coords[0])
        corners = {tuple(c) for piece in loop.corners for c in piece.tolist()}
        starts = [centre + 0.995 * (np.asarray(c) - centre) for c in sorted(corners)]
        starts.append(centre)
        # a move leaves within its stated exit-time bound (the width along xi over the flow's
        # margin): followed that long and a little more, up to a minute
        bound = step["exit_time_bound"]
        horizon = CAP if bound is None else min(1.05 * bound + 0.1, CAP)
        for k, start in enumerate(starts):
            for kind in ("kept", "against", "random"):
                outcome, gap = loop.run(start.tolist(), d, kind, dt=0.005, horizon=horizon, seed=k)
                assert outcome != "wrong", (step["step"], start, kind, gap)
                if loop.direction is None:
                    assert outcome == "held", (step["step"], start, kind)
                elif horizon < CAP:
                    assert outcome == "exit", (step["step"], start, kind, bound)


@pytest.mark.slow
def test_a_push_off_the_plan_is_replanned_on_cells(compiled: Any) -> None:
    executor = tlmpc.executor(compiled)
    bound = RATIO * executor.mission.robot.max_speed
    dt = default_dt(executor.plan, executor.mission.robot.max_speed + bound)
    target = np.array([9.0, 5.5])
    declared = make_disturbance("adversarial", bound, 0, dt)

    def push(t: float, point: Any, running: Executor) -> Any:
        if t < 0.5 * dt:
            return (target - point) / dt - running.velocity(point)
        return declared(t, point, running)

    run = run_closed_loop(executor, push, bound=bound, dt=dt)
    kinds = [r.kind for r in run.recoveries]
    assert "replan" in kinds, run.recoveries
    assert "no_plan" not in kinds, run.recoveries
    # read at the first sample after the push: nothing later
    assert all(r.time <= 1.5 * dt for r in run.recoveries), run.recoveries
    assert all(step.kind == "cell" for step in executor.plan.steps)
    verdict = verify_document(run.trace)
    assert verdict.satisfied, [v.message for v in verdict.violations]
    assert run.completed
    points = [shapely.Point(x, y) for _, x, y in run.trace["points"]]
    assert all(shapely.box(0, 0, 10, 10).contains(p) for p in points)
    p1 = shapely.Polygon(_mission()["regions"]["p1"])
    assert p1.contains(points[-1])
