"""The `length` cost bounds the channel's shortest path, which the controllers follow.

The cost of a plan that ends by staying is the polyline from the start through the midpoints of
the crossed edges: one path through the plan's portals.  The channel's shortest path (the
funnel the controllers follow, tlmpc/control/channel.py) from the start to the last midpoint
through the same portals can only be shorter; on a straight corridor the two meet.
"""

from __future__ import annotations

import math
from itertools import pairwise
from typing import Any

from hypothesis import HealthCheck, given, settings
from strategies import missions

from tlmpc.control.channel import Portal, funnel
from tlmpc.pipeline.stages import ABSTRACTION, MISSION, WITNESS


def _polyline(points: list[tuple[float, float]]) -> float:
    return sum(math.dist(a, b) for a, b in pairwise(points))


@settings(
    deadline=None,
    max_examples=25,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(missions())
def test_length_cost_bounds_the_channel_shortest_path(document: dict[str, Any]) -> None:
    import yaml

    from tlmpc.base.errors import TlmpcError
    from tlmpc.pipeline.stages import compile_mission

    try:
        result = compile_mission("random.yaml", text=yaml.safe_dump(document), until="plan")
    except TlmpcError:
        return  # no plan for this task: nothing to compare
    abstraction = result.compilation.get(ABSTRACTION)
    witness = result.compilation.get(WITNESS)
    mission = result.compilation.get(MISSION)
    if not witness.is_stay or witness.passages or witness.metric != "length":
        return
    path = [*witness.prefix, *witness.cycle]
    portals, midpoints = [], []
    for tri, nxt in pairwise(path):
        corners = abstraction.corners(tri).tolist()
        edge = abstraction.neighbors[tri].tolist().index(nxt)
        left, right = tuple(corners[(edge + 2) % 3]), tuple(corners[(edge + 1) % 3])
        portals.append(Portal((left[0], left[1]), (right[0], right[1])))
        midpoints.append(((left[0] + right[0]) / 2.0, (left[1] + right[1]) / 2.0))
    start = (float(mission.robot.start[0]), float(mission.robot.start[1]))
    if not portals:
        return
    crossings = funnel(start, portals[:-1], midpoints[-1])
    shortest = _polyline([start, *crossings, midpoints[-1]])
    through_midpoints = _polyline([start, *midpoints])
    # the first plan's cost is the midpoint polyline; a re-plan kept for its shorter path
    # (tlmpc.pipeline.shortest) weighs the moves by their pieces of the path instead
    if witness.stats.get("path_length") == witness.stats.get("path_lengths", [None])[0]:
        assert math.isclose(witness.prefix_cost, through_midpoints, rel_tol=1e-6, abs_tol=1e-6)
    assert shortest <= through_midpoints * (1 + 1e-12) + 1e-12
