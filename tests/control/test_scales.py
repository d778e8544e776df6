"""Controllers and trajectories stay sound at every scale, checked by an independent checker.

The paper's Example 1 is compiled with its map scaled from nanometres to thousands of
kilometres, moved up to 1e8 from the origin, and max_speed from 1e-9 to 1e6.  The checker
shares no code with tlmpc: vertex conditions in exact rational arithmetic (outward normals
left unnormalised, so no square roots), the speed bound squared, and the flow of each step's
affine field by scipy's matrix exponential compared with the trace's samples.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import expm

from tlmpc.api import compile as compile_mission

EXAMPLE_1: dict[str, Any] = {
    "version": 1,
    "name": "scaled-example-1",
    "workspace": {"boundary": [[0, 0], [10, 0], [10, 10], [0, 10]]},
    "regions": {
        "p1": [[0.5, 0.5], [3.0, 0.5], [3.0, 3.0], [0.5, 3.0]],
        "p2": [[1.0, 6.5], [4.0, 6.0], [3.5, 9.0], [1.0, 9.0]],
        "p3": [[6.5, 6.5], [9.5, 6.5], [9.5, 9.5], [6.5, 9.5]],
        "p4": [[7.0, 1.0], [9.5, 1.5], [9.0, 4.0], [6.5, 3.5]],
    },
    "robot": {"start": [1.5, 1.5], "max_speed": 1.0},
    "task": ["visit p2 then p3 then p4 then return to p1 while avoiding p2 and p3"],
}


def _scaled(size: float, offset: tuple[float, float], speed: float) -> dict[str, Any]:
    def move(point: list[float]) -> list[float]:
        return [offset[0] + size * point[0] / 10, offset[1] + size * point[1] / 10]

    mission = dict(EXAMPLE_1)
    mission["workspace"] = {"boundary": [move(p) for p in EXAMPLE_1["workspace"]["boundary"]]}
    mission["regions"] = {
        name: [move(p) for p in points] for name, points in EXAMPLE_1["regions"].items()
    }
    mission["robot"] = {"start": move(EXAMPLE_1["robot"]["start"]), "max_speed": speed}
    return mission


def _exact(value: float) -> Fraction:
    return Fraction(value)


def _check_vertex_conditions(step: dict[str, Any], max_speed: float) -> None:
    vertices = [(_exact(x), _exact(y)) for x, y in step["vertices"]]
    velocities = [(_exact(u), _exact(v)) for u, v in step["vertex_velocities"]]
    bound = _exact(max_speed) * (1 + Fraction(1, 10**9))
    for u, v in velocities:
        assert u * u + v * v <= bound * bound
    exit_edge = step["exit_edge"]
    for facet in range(3):
        (ax, ay), (bx, by) = vertices[(facet + 1) % 3], vertices[(facet + 2) % 3]
        normal = (by - ay, -(bx - ax))  # outward for a counter-clockwise triangle, unnormalised
        for vertex in range(3):
            if vertex == facet and facet != exit_edge:
                continue  # the vertex opposite a facet is not on it
            across = normal[0] * velocities[vertex][0] + normal[1] * velocities[vertex][1]
            if facet == exit_edge:
                assert across > 0, (step["step"], facet, vertex)
            else:
                assert across < 0, (step["step"], facet, vertex)


def _check_flow(trace: dict[str, Any], steps: list[dict[str, Any]], size: float) -> None:
    points = np.asarray(trace["points"])
    step_of = trace["steps"]
    start = 0
    for k in range(1, len(points) + 1):
        if k < len(points) and step_of[k] == step_of[start]:
            continue
        step = steps[step_of[start]]
        if step["exit_edge"] is not None:
            gain, offset = np.asarray(step["K"]), np.asarray(step["g"])
            center = np.asarray(step["vertices"]).mean(axis=0)
            field = np.zeros((3, 3))
            field[:2, :2], field[:2, 2] = gain, gain @ center + offset
            entry = points[start - 1] if start else points[0]  # the previous step's crossing
            t0, first = entry[0], entry[1:]
            for t, x, y in points[start:k]:
                expected = (expm((t - t0) * field) @ [*(first - center), 1.0])[:2] + center
                assert np.linalg.norm(expected - [x, y]) <= 1e-6 * size
        start = k


@settings(deadline=None, max_examples=25)
@given(
    size_exponent=st.integers(-6, 6),
    speed_exponent=st.integers(-9, 6),
    offset_exponent=st.integers(0, 8),
    direction=st.sampled_from([(1.0, 1.0), (-1.0, 0.5), (0.0, -1.0)]),
)
def test_compiled_controllers_are_sound_at_any_scale(
    size_exponent: int, speed_exponent: int, offset_exponent: int, direction: tuple[float, float]
) -> None:
    size, speed = 10.0**size_exponent, 10.0**speed_exponent
    # Float64 holds a map of this size this far out only down to ~1e-10 of its size.
    reach = min(10.0**offset_exponent, size * 1e6) if offset_exponent else 0.0
    offset = (direction[0] * reach, direction[1] * reach)
    result = compile_mission(_scaled(size, offset, speed), until="verify")
    assert result.summary["verdict"]["satisfied"] is True
    controllers = result.artifacts["controllers.json"]
    for step in controllers["steps"]:
        _check_vertex_conditions(step, speed)
    trace = result.artifacts["trace.json"]
    points = np.asarray(trace["points"])
    gaps = np.diff(points, axis=0)
    moved = np.hypot(gaps[:, 1], gaps[:, 2])
    assert np.all(moved <= speed * gaps[:, 0] * (1 + 1e-6) + 1e-9 * size)
    _check_flow(trace, controllers["steps"], size)
