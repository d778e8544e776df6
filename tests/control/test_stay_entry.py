"""A plan that ends by staying is pulled to the nearest point of its stay triangle's entry edge
(where its cost ends), not toward the triangle's incenter.

Oracle: the shortest path inside the corridor before the stay triangle to the entry edge, a
visibility graph on shapely geometry (tests/oracles/shortest_paths.py), independent of the
funnel.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shortest_paths import geodesic
from test_follow import _BentCorridor, strip_plan, strips

from tlmpc.control import channel
from tlmpc.control.channel import ChannelStep, Point


def _steps(abstraction: Any, count: int) -> list[ChannelStep]:
    steps = []
    for t in range(count):
        corners = [(float(x), float(y)) for x, y in abstraction.corners(t).tolist()]
        after = np.flatnonzero(abstraction.neighbors[t] == t + 1)
        steps.append(
            ChannelStep(
                corners=(corners[0], corners[1], corners[2]),
                exit_edge=int(after[0]) if len(after) else None,
                clearance=0.0,
            )
        )
    return steps


@settings(deadline=None, max_examples=60, suppress_health_check=[HealthCheck.filter_too_much])
@given(strips(), st.floats(0.05, 0.9), st.floats(0.05, 0.9))
def test_a_stay_is_pulled_to_the_nearest_point_of_its_entry_edge(
    strip: Any, u: float, v: float
) -> None:
    planned = strip_plan(*strip)
    if planned is None:
        return
    abstraction, _witness, triangles = planned
    count = len(triangles)
    weights = np.array([u, v, 1.0]) / (u + v + 1.0)
    sx, sy = (abstraction.corners(0).T @ weights).tolist()
    start: Point = (sx, sy)
    steps = _steps(abstraction, count)
    moving = list(range(count - 1))
    crossings = channel._pulled(steps, moving, [(0.0, 0.0)] * len(moving), start, nearest=True)
    assert len(crossings) == len(moving)
    length = sum(math.dist(a, b) for a, b in itertools.pairwise([start, *crossings]))
    before = shapely.union_all(
        [shapely.Polygon(abstraction.corners(t).tolist()) for t in range(count - 1)]
    )
    entry = channel.exit_portal(steps[count - 2])
    best = geodesic(before, start, shapely.LineString([entry.left, entry.right]))
    assert best - 1e-9 <= length <= best * (1 + 1e-6) + 1e-9
    # ... and the midpoint end is never shorter
    middle = channel._pulled(steps, moving, [(0.0, 0.0)] * len(moving), start)
    to_middle = sum(math.dist(a, b) for a, b in itertools.pairwise([start, *middle]))
    assert length <= to_middle + 1e-9


def test_round_a_bend_the_stay_is_pulled_to_its_entry_edge_from_the_inner_corner() -> None:
    """An L-shaped corridor (east, then north), the stay triangle at its north end: the path
    bends at the inner corner and runs from there to the nearest point of the stay's entry
    edge (the visibility graph's length, the funnel's crossings not used)."""
    bent = _BentCorridor()
    count = len(bent.triangles)
    steps = _steps(bent.abstraction, count)
    moving = list(range(count - 1))
    crossings = channel._pulled(steps, moving, [(0.0, 0.0)] * len(moving), bent.start, nearest=True)
    length = sum(math.dist(a, b) for a, b in itertools.pairwise([bent.start, *crossings]))
    before = shapely.union_all(
        [shapely.Polygon(bent.abstraction.corners(t).tolist()) for t in moving]
    )
    entry = channel.exit_portal(steps[count - 2])
    best = geodesic(before, bent.start, shapely.LineString([entry.left, entry.right]))
    assert length == pytest.approx(best, rel=1e-9)
    assert (2.5, 0.5) in crossings  # the inner corner


def _straight_corridor() -> list[ChannelStep]:
    """The channel of a straight corridor (0, 0)-(3, 1) cut into six triangles, ending by
    staying in the last: its stay triangle is entered by the diagonal from (2, 1) to (3, 0)."""
    planned = strip_plan(
        [(0.0, 1.0), (1.0, 1.0), (2.0, 1.0), (3.0, 1.0)],
        [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (3.0, 0.0)],
    )
    assert planned is not None
    abstraction, _witness, triangles = planned
    return _steps(abstraction, len(triangles))


def test_the_stay_piece_runs_from_the_entry_to_the_incenter() -> None:
    """The stay's piece starts where the path crosses the entry edge (in a straight corridor,
    nearer the start than the edge's midpoint is: the entry edge is the diagonal from (2, 1)
    to (3, 0), the start low on the left) and ends at the stay triangle's incenter (the stay
    field's target)."""
    steps = _straight_corridor()
    pieces = channel.channel_pieces(steps, None, (0.2, 0.2))
    stay = pieces[-1]
    assert stay.entry == pieces[-2].exit
    entry = channel.exit_portal(steps[-2])
    assert entry.left == (2.0, 1.0)
    assert entry.right == (3.0, 0.0)
    assert stay.entry[0] + stay.entry[1] == pytest.approx(3.0)  # on the diagonal
    assert math.dist((0.2, 0.2), stay.entry) < math.dist((0.2, 0.2), (2.5, 0.5)) - 0.1
    corners = steps[-1].corners
    sides = [math.dist(corners[(i + 1) % 3], corners[(i + 2) % 3]) for i in range(3)]
    incenter = tuple(
        sum(w * c[k] for w, c in zip(sides, corners, strict=True)) / sum(sides) for k in (0, 1)
    )
    assert stay.exit == incenter


def test_a_stay_is_not_asked_to_follow_its_piece() -> None:
    """The following program gets every moving step that is neither a vertex passage nor a
    needle, and no stay: on the reach-avoid spec's plan (it ends by staying)."""
    from unittest import mock

    from tlmpc.control import follow, synthesize
    from tlmpc.control.follow import NEEDLE
    from tlmpc.pipeline.stages import ABSTRACTION, MISSION, WITNESS, compile_mission

    source = Path(__file__).resolve().parents[2] / "specs" / "reach-avoid.yaml"
    compilation = compile_mission(source, until="plan").compilation
    mission, mesh, witness = (
        compilation.get(MISSION),
        compilation.get(ABSTRACTION),
        compilation.get(WITNESS),
    )
    assert witness.is_stay
    seen: list[int] = []
    original = follow.solve_follow

    def counted(*args: Any, **keywords: Any) -> Any:
        seen.append(len(args[5]))
        return original(*args, **keywords)

    with mock.patch.object(follow, "solve_follow", counted):
        synthesize(mesh, witness, mission.robot)
    route = [*witness.prefix, *witness.cycle]
    passages = dict(witness.passages)
    expected = 0
    for index, triangle in enumerate(route[:-1]):  # the last is the stay
        corners = mesh.corners(triangle)
        sides = [math.dist(corners[i].tolist(), corners[i - 1].tolist()) for i in range(3)]
        area = shapely.Polygon(corners.tolist()).area
        thin = 2 * area / max(sides) < NEEDLE * max(sides)
        if index not in passages and not thin:
            expected += 1
    assert seen == [expected]


def test_without_reach_rounds_the_stay_is_entered_at_the_nearest_inset_point() -> None:
    """A straight corridor whose stay triangle is entered by the diagonal from (2, 1) to
    (3, 0), the start low on the left: with the portal insets alone (no widening round) the
    path runs straight to the diagonal's inset end nearest the start, (2.03, 0.97)."""
    from unittest import mock

    steps = _straight_corridor()
    with mock.patch.object(channel, "REACH_ROUNDS", 0):
        pieces = channel.channel_pieces(steps, None, (0.2, 0.2))
    inset = channel.PORTAL_INSET
    assert pieces[-1].entry == pytest.approx((2.0 + inset, 1.0 - inset), abs=1e-12)


def test_the_last_corner_is_the_last_bend_before_the_end() -> None:
    """A polyline bending twice: its last corner is the second bend; a straight one has none
    but the start."""
    zigzag = [(1.0, 0.0), (1.0, 1.0), (2.0, 1.0), (3.0, 1.0)]
    assert channel._last_corner((0.0, 0.0), zigzag) == (1.0, 1.0)
    assert channel._last_corner((0.0, 0.0), [(1.0, 1.0), (2.0, 2.0)]) == (0.0, 0.0)
