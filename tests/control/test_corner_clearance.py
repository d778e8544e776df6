"""The channel's path keeps its clearance from a region's own corner it bends round, and a
visit that enters a region and leaves it across one corner goes that deep.

Oracles: shapely's distances from the corner, and from the region's boundary, to the pulled
path (a polyline the test builds from the pieces); no tlmpc geometry."""

from __future__ import annotations

import math

import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.control.channel import REACH_CAP, ChannelStep, channel_pieces

RADIUS = 2.0


def _ray(angle: float, length: float = RADIUS) -> tuple[float, float]:
    return (length * math.cos(math.radians(angle)), length * math.sin(math.radians(angle)))


def _fan(angles: list[float], clearance: float, *, inside: int | None = None) -> list[ChannelStep]:
    """Triangles (v, p_i, p_i+1) about v = (0, 0), counter-clockwise, the path crossing the
    rays (v, p_i) in turn and leaving the last by its outer edge; v lies on a region's own
    boundary.  ``inside``: that triangle is a region's corner (all its corners on the
    region's boundary, entered there)."""
    steps = []
    for i in range(len(angles) - 1):
        last = i == len(angles) - 2
        steps.append(
            ChannelStep(
                corners=((0.0, 0.0), _ray(angles[i]), _ray(angles[i + 1])),
                exit_edge=0 if last else 1,
                clearance=clearance,
                labelled=(True, True, True) if i == inside else (True, False, False),
                entered=i == inside,
            )
        )
    return steps


def _path(steps: list[ChannelStep], start: tuple[float, float]) -> shapely.LineString:
    pieces = channel_pieces(steps, None, start)
    return shapely.LineString([start, *(piece.exit for piece in pieces)])


@settings(deadline=None, max_examples=200)
@given(
    st.lists(st.floats(20.0, 100.0), min_size=2, max_size=4),
    st.floats(0.02, 0.25),
)
def test_the_path_round_a_regions_corner_keeps_its_clearance(
    spans: list[float], share: float
) -> None:
    angles = [-90.0]
    for span in spans:
        angles.append(angles[-1] + span)
    clearance = share * RADIUS
    # the insets can keep it: at most the cap of each ray, through the widest span
    widest = max(spans)
    if clearance / math.cos(math.radians(widest / 2.0)) > REACH_CAP * RADIUS * 0.9:
        return
    steps = _fan(angles, clearance)
    start = _ray(angles[0] + 1.0, 0.9 * RADIUS)
    path = _path(steps, start)
    assert path.distance(shapely.Point(0.0, 0.0)) >= clearance * (1.0 - 1e-6)


def test_a_square_corner_without_the_rounds_would_be_cut() -> None:
    """The plain insets keep the clearance along each ray only: the chord between two rays
    at a right angle passes cos 45 degrees of it from the corner.  With the rounds it keeps
    all of it."""
    steps = _fan([-90.0, 0.0, 90.0, 180.0], 0.2)
    start = _ray(-89.0, 0.9 * RADIUS)
    assert _path(steps, start).distance(shapely.Point(0.0, 0.0)) >= 0.2 * (1.0 - 1e-6)


@settings(deadline=None, max_examples=100)
@given(st.floats(40.0, 120.0), st.floats(0.02, 0.12))
def test_a_visit_across_a_corner_goes_as_deep_as_the_clearance(
    opening: float, share: float
) -> None:
    """The region is the wedge between the rays at 0 and ``opening`` degrees; the plan
    enters it in its corner triangle and leaves it at once."""
    clearance = share * RADIUS
    angles = [-60.0, 0.0, opening, opening + 60.0]
    steps = _fan(angles, clearance, inside=1)
    start = _ray(-59.0, 0.9 * RADIUS)
    path = _path(steps, start)
    far = 100.0
    region = shapely.Polygon([(0.0, 0.0), _ray(0.0, far), _ray(opening, far)])
    inside = path.intersection(region)
    samples = [inside.interpolate(k / 4000.0, normalized=True) for k in range(4001)]
    depth = max(region.exterior.distance(point) for point in samples)
    assert depth >= clearance * (1.0 - 1e-3)


def test_one_round_moves_a_path_that_touches_no_inset() -> None:
    """A straight path round a region's corner that touches none of the insets (it crosses
    the rays 0.3 and 0.23 from the corner, beyond the 0.2 they keep) but passes 0.183 from
    it: the ends are moved from where the path crosses, so one round is enough (widening the
    insets by the ratio would leave them short of the crossings, and the path where it was)."""
    from unittest import mock

    from tlmpc.control import channel

    steps = _fan([-90.0, 0.0, 90.0, 180.0], 0.2)
    with mock.patch.object(channel, "REACH_ROUNDS", 0):
        straight = _path(steps, (0.95, -0.5))
    assert len(straight.coords) == 4
    assert straight.distance(shapely.Point(0.0, 0.0)) < 0.19
    # (the reach's widening alone moves this path too: without it, the clearance's)
    with mock.patch.multiple(channel, REACH_ROUNDS=1, REACH_GAIN=0.0):
        moved = _path(steps, (0.95, -0.5))
    assert moved.distance(shapely.Point(0.0, 0.0)) >= 0.2
