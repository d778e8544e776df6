"""The executor re-plans through compile's own planning entry, U-turn refinement included.

Two dead-end bays 0.2 wide: the compiled plan for ``F t1 & F G base & G(c -> F t2)`` turns
around in bay 1 only (it never enters ``c``).  A push into ``c`` obliges a visit to ``t2`` at
the end of bay 2 and back, a U-turn the compiled mesh cannot realise without a split there.
The re-plan must refine the mesh as compile does, and the run must satisfy the task (checked
by the verifier, which shares no code with planning or the executor).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import shapely

import tlmpc
from tlmpc.runtime import Executor, run_closed_loop
from tlmpc.runtime.closed_loop import default_dt
from tlmpc.verify import verify_document

FloatArray = np.ndarray[Any, np.dtype[np.float64]]

TWO_BAYS = [
    (0, 0), (10, 0), (10, 2), (8.2, 2), (8.2, 5), (8.0, 5), (8.0, 2),
    (3.2, 2), (3.2, 5), (3.0, 5), (3.0, 2), (0, 2),
]  # fmt: skip


def _rect(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


def _mission() -> dict[str, Any]:
    return {
        "version": 1,
        "workspace": {"boundary": [list(p) for p in TWO_BAYS]},
        "regions": {
            "t1": _rect(3.0, 4.5, 3.2, 5.0),
            "t2": _rect(8.0, 4.5, 8.2, 5.0),
            "base": _rect(0.0, 0.0, 0.8, 0.8),
            "c": _rect(6.0, 0.0, 7.0, 0.8),
        },
        "robot": {"start": [1.5, 1.0], "max_speed": 1.0},
        "ltl": "F t1 & F G base & G(c -> F t2)",
        # the U-turn below is set up on the plain mesh (goals not cored)
        "options": {"goal_depth": 0},
    }


def test_a_replan_that_needs_a_u_turn_refines_the_mesh() -> None:
    compiled = tlmpc.compile(_mission())
    executor = tlmpc.executor(compiled)
    bay2 = shapely.box(8.0, 2.0, 8.2, 5.0)
    compiled_mesh = executor.abstraction
    assert not any(
        bay2.contains(shapely.Point(compiled_mesh.corners(s.triangle).mean(axis=0)))
        for s in executor.plan.steps
    ), "the compiled plan stays out of bay 2"
    dt = default_dt(executor.plan, 1.0)
    target = np.array([6.5, 0.4])  # inside c

    def push(t: float, point: FloatArray, running: Executor) -> FloatArray:
        if 0.0 <= t < dt:
            velocity: FloatArray = (target - point) / dt - running.velocity(point)
            return velocity
        return np.zeros(2)

    run = run_closed_loop(executor, push, bound=0.0, dt=dt)
    assert "replan" in [r.kind for r in run.recoveries]
    assert run.progress.status != "no_plan"
    assert executor.abstraction.num_triangles > compiled_mesh.num_triangles  # split in bay 2
    assert run.progress.visits["t2"] >= 1
    verdict = verify_document(run.trace)
    assert verdict.satisfied, verdict.violations
