"""The pursuit of a corner under command periods that vary, as on a real robot.

The executor slows the pursuit so that a command held for the *last* period lands on the
corner; when the next period is longer, the held command carries the robot past it.  That
move must count as arriving (the corner lies between the two measured points), so the run
goes on into the plan's next triangle without a recovery.  Independent checks: the robot's
own positions show the overshoot happened, and the verifier (no shared code) accepts the run.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import tlmpc
from tlmpc.verify import verify_document


def _corner_mission() -> dict[str, Any]:
    return {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, 10, 10]}},
        "regions": {"a": {"rect": [2, 2, 5, 5]}, "b": {"rect": [5, 5, 8, 8]}},
        "robot": {"start": [3, 3], "max_speed": 1.0},
        "ltl": "G(a | b) & F b",
    }


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_held_command_past_the_corner_counts_as_arrival(seed: int) -> None:
    compiled = tlmpc.compile(_corner_mission())
    executor = tlmpc.executor(compiled)
    corner_step = next(i for i, s in enumerate(executor.plan.steps) if s.is_vertex)
    corner = np.asarray(executor.plan.steps[corner_step].target, dtype=float)
    rng = np.random.default_rng(seed)
    point = np.asarray(executor.mission.robot.start, dtype=float)
    t = 0.0
    overshoot = False
    points = [(t, *point)]
    for _ in range(4000):
        u = np.asarray(executor.command(tuple(point), t), dtype=float)
        period = float(rng.choice([0.01, 0.05, 0.4]))  # the next period is not the last one
        previous, point = point, point + period * u
        t += period
        points.append((t, *point))
        if float((corner - previous) @ (corner - point)) < 0.0:
            overshoot = True
        if executor.progress.step > corner_step and executor.controller.exit_edge is None:
            break  # in the final stay of b
    executor.command(tuple(point), t)
    assert overshoot, "a longer period carried the robot past the corner"
    assert [r.kind for r in executor.recoveries] == []
    assert executor.progress.visits["b"] >= 1
    assert executor.progress.status == "following"
    trace = dict(compiled.artifacts["trace.json"])
    trace["points"] = [list(p) for p in points]
    trace.pop("loop_start", None)
    assert verify_document(trace).satisfied
