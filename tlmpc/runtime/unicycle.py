"""Differential drive by feedback linearisation of the point ahead of the axle.

A unicycle x' = v cos θ, y' = v sin θ, θ' = ω cannot follow a velocity field with its axle
centre (it cannot move sideways), but the point p = (x, y) + l (cos θ, sin θ) at distance
l > 0 ahead of the axle can: p' = R(θ) diag(1, l) (v, ω), which is invertible, so

    [v, ω] = [[cos θ, sin θ], [−sin θ / l, cos θ / l]] u

makes p' = u exactly, for any field u.  The planned field is therefore tracked by p (the
*reference point*: its position is what the labels, the plan and the trace refer to).  Speed:
|p'| = |u| <= max_speed is kept exactly, and then |v| <= max_speed and |ω| <= max_speed / l.
The body around the axle reaches l further than the reference point's path in the worst case,
so the obstacles are inflated by l (:func:`unicycle_inflation`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from tlmpc.abstraction.model import FloatArray
from tlmpc.mission.body import unicycle_inflation as unicycle_inflation
from tlmpc.mission.model import Robot


def reference_point(pose: Sequence[float], robot: Robot) -> FloatArray:
    """The point the plan steers: the pose for a point robot, the point ahead for a unicycle."""
    if robot.model != "unicycle":
        return np.array([float(pose[0]), float(pose[1])])
    theta = float(pose[2])
    return np.array(
        [
            float(pose[0]) + robot.offset * math.cos(theta),
            float(pose[1]) + robot.offset * math.sin(theta),
        ]
    )


def unicycle_command(theta: float, u: FloatArray, offset: float) -> tuple[float, float]:
    """(v, ω) that move the point ``offset`` ahead of the axle with velocity ``u``."""
    cos, sin = math.cos(theta), math.sin(theta)
    forward = cos * float(u[0]) + sin * float(u[1])
    turn = (-sin * float(u[0]) + cos * float(u[1])) / offset
    return forward, turn


def unicycle_flow(
    pose: Sequence[float], forward: float, turn: float, dt: float
) -> tuple[float, float, float]:
    """The unicycle's exact pose after ``dt`` at constant (v, ω) (an arc, or a line)."""
    x, y, theta = float(pose[0]), float(pose[1]), float(pose[2])
    heading = theta + turn * dt
    if abs(turn * dt) < 1e-9:  # a straight line, to rounding (the arc formula divides by ω)
        middle = theta + 0.5 * turn * dt
        return x + forward * dt * math.cos(middle), y + forward * dt * math.sin(middle), heading
    radius = forward / turn
    return (
        x + radius * (math.sin(heading) - math.sin(theta)),
        y - radius * (math.cos(heading) - math.cos(theta)),
        heading,
    )
