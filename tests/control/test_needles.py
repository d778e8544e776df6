"""Needles (``min_angle: null``): a plan through a sliver corner no field can push from is
replaced by one through corners that can, instead of failing inside the control stage.

The missions have a region 1e-8 thick and 6-8 long (its tip and the free-space triangles
fanning onto its short edge have corners of about 1e-9 radians, where no velocity within
max_speed pushes 1e-9 x max_speed, the controllers' stated tolerance). Each compiled plan is
verified by the compile's own verifier and every step is run by the independent adversary
(tests/oracles/adversary.py) at zero disturbance; the corner angles are recomputed here.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from adversary import check_step

import tlmpc


def _needle(tip: str, task: str, start: tuple[float, float]) -> dict[str, Any]:
    x0, x1, y, h = 2.0, 9.0, 4.0, 1e-8
    shapes = {
        "left": [[x0, y], [x1, y], [x1, y + h]],
        "right": [[x0, y], [x1, y], [x0, y + h]],
        "mid": [[x0, y], [x1, y], [(x0 + x1) / 2, y + h]],
    }
    return {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [10, 0], [10, 10], [0, 10]]},
        "regions": {"b": shapes[tip], "c": [[8.5, 0.2], [9.8, 0.2], [9.8, 0.8]]},
        "robot": {"start": list(start), "max_speed": 1.0},
        "options": {"min_angle": None},
        "task": [task],
    }


def _smallest_angle(vertices: np.ndarray) -> float:
    angles = []
    for i in range(3):
        u, w = vertices[(i + 1) % 3] - vertices[i], vertices[(i + 2) % 3] - vertices[i]
        angles.append(math.atan2(abs(u[0] * w[1] - u[1] * w[0]), float(u @ w)))
    return min(angles)


@pytest.mark.parametrize("tip", ["left", "right", "mid"])
@pytest.mark.parametrize("task", ["visit b then c", "patrol b and c"])
@pytest.mark.parametrize("start", [(0.3, 0.1), (5.0, 0.1), (9.6, 9.5)])
def test_a_needle_plans_and_every_step_holds(
    tip: str, task: str, start: tuple[float, float]
) -> None:
    mission = _needle(tip, task, start)
    compiled = tlmpc.compile(mission, until="verify")
    assert compiled.summary["verdict"]["satisfied"] is True
    controllers = compiled.artifacts["controllers.json"]
    for step in controllers["steps"]:
        check_step(step, 0.0, controllers["max_speed"])


def test_the_needle_missions_have_sliver_triangles() -> None:
    compiled = tlmpc.compile(_needle("left", "visit b then c", (5.0, 0.1)), until="abstraction")
    mesh = compiled.artifacts["abstraction.json"]
    vertices = np.asarray(mesh["vertices"])
    smallest = min(_smallest_angle(vertices[np.asarray(t)]) for t in mesh["triangles"])
    assert smallest < 2e-9  # sin(a / 2) below the tolerance of 1e-9
