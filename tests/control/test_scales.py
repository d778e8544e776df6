"""Controllers and trajectories stay sound at every scale, checked by an independent checker.

The paper's Example 1 is compiled with its map scaled from nanometres to thousands of
kilometres, moved up to 1e8 from the origin, and max_speed from 1e-9 to 1e6 (as long as
crossing the map takes no longer than a trace holds, 1e12 s: slower is S010).  The checker
(tests/oracles/trace_check.py) shares no code with tlmpc: vertex conditions in exact rational
arithmetic, the speed bound, and the flow of each step's affine field by scipy's matrix
exponential compared with the trace's samples.
"""

from __future__ import annotations

import math
from typing import Any

from hypothesis import assume, given, settings
from hypothesis import strategies as st
from trace_check import check_flow, check_speed, check_vertex_conditions

from tlmpc.api import compile as compile_mission
from tlmpc.mission.load import MAX_CROSSING_SECONDS

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
    assume(size * math.sqrt(2) / speed <= MAX_CROSSING_SECONDS)
    # Float64 holds a map of this size this far out only down to ~1e-10 of its size.
    reach = min(10.0**offset_exponent, size * 1e6) if offset_exponent else 0.0
    offset = (direction[0] * reach, direction[1] * reach)
    result = compile_mission(_scaled(size, offset, speed), until="verify")
    assert result.summary["verdict"]["satisfied"] is True
    controllers = result.artifacts["controllers.json"]
    for step in controllers["steps"]:
        check_vertex_conditions(step, speed)
    trace = result.artifacts["trace.json"]
    check_speed(trace, speed, size)
    check_flow(trace, controllers["steps"], size)
