"""Exit insets widened where a piece heads toward the kept facet through an exit end.

Oracle: σ measured with shapely as the rate at which the piece closes on the facet's line
(distance at the entry minus distance at the exit, over the piece's length), the facet being
the triangle's other edge through that end; no tlmpc geometry."""

from __future__ import annotations

import math

import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from tlmpc.control import channel
from tlmpc.control.channel import REACH_CAP, REACH_GAIN, ChannelStep, _reachable

coordinate = st.floats(-4.0, 4.0, allow_nan=False)


def _closing_rate(
    entry: tuple[float, float], exit_: tuple[float, float], a: object, c: object
) -> float:
    line = shapely.LineString([a, c])
    # the whole line, not the segment: extend it far both ways
    (ax, ay), (cx, cy) = line.coords
    dx, dy = cx - ax, cy - ay
    far = shapely.LineString([(ax - 1e3 * dx, ay - 1e3 * dy), (cx + 1e3 * dx, cy + 1e3 * dy)])
    before = far.distance(shapely.Point(entry))
    after = far.distance(shapely.Point(exit_))
    return float(before - after) / math.dist(entry, exit_)


@settings(deadline=None, max_examples=300)
@given(
    st.lists(coordinate, min_size=6, max_size=6),
    st.integers(0, 2),
    st.floats(0.0, 1.0),
    st.floats(0.0, 1.0),
    st.floats(0.05, 0.95),
)
def test_an_end_is_widened_to_the_gain_times_the_closing_rate(
    coords: list[float], exit_edge: int, s: float, t: float, u: float
) -> None:
    corners = ((coords[0], coords[1]), (coords[2], coords[3]), (coords[4], coords[5]))
    area = shapely.Polygon(corners).area
    assume(area > 0.05)
    if shapely.Polygon(corners).exterior.is_ccw is False:
        corners = (corners[0], corners[2], corners[1])
    e = exit_edge
    left, right = corners[(e + 2) % 3], corners[(e + 1) % 3]
    opposite = corners[e]
    # an entry point inside the triangle (on the segment from the opposite corner toward
    # the exit edge) and an exit point on the exit edge
    on_exit = (left[0] + u * (right[0] - left[0]), left[1] + u * (right[1] - left[1]))
    inner = (
        opposite[0] + s * (on_exit[0] - opposite[0]) * 0.9,
        opposite[1] + s * (on_exit[1] - opposite[1]) * 0.9,
    )
    entry = (inner[0] + t * 0.01, inner[1])
    assume(math.dist(entry, on_exit) > 1e-3)
    assume(shapely.Polygon(corners).buffer(1e-9).contains(shapely.Point(entry)))
    step = ChannelStep(corners=corners, exit_edge=e, clearance=0.1)
    base = (channel.PORTAL_INSET, channel.PORTAL_INSET)
    widened = _reachable(step, base, entry, on_exit)
    for side, end in ((0, left), (1, right)):
        rate = _closing_rate(entry, on_exit, end, opposite)
        want = min(REACH_CAP, REACH_GAIN * rate) if REACH_GAIN * rate > base[side] else base[side]
        assert widened[side] == pytest.approx(want, abs=1e-9)


def test_a_piece_running_away_from_both_facets_keeps_its_insets() -> None:
    corners = ((0.0, 0.0), (4.0, 0.0), (0.0, 4.0))
    step = ChannelStep(corners=corners, exit_edge=0, clearance=0.1)  # exit: (4, 0) - (0, 4)
    # from near the right angle straight out along the diagonal: away from both legs
    assert _reachable(step, (0.03, 0.03), (0.5, 0.5), (2.0, 2.0)) == (0.03, 0.03)
    # heading for the exit edge's end (4, 0) while closing on the leg y = 0 (the other facet
    # through that end): that end alone is widened, to REACH_GAIN times the closing rate
    entry, exit_ = (0.2, 1.0), (3.7, 0.3)
    rate = 0.7 / math.dist(entry, exit_)
    widened = _reachable(step, (0.03, 0.03), entry, exit_)
    assert widened[0] == 0.03
    assert widened[1] == pytest.approx(REACH_GAIN * rate)
