"""Visits go into the region: the goal depth, by default a quarter of the region's inradius
but at most what the robot covers in 0.1 s at max_speed.

The oracle is geometry the test knows exactly: rectangular regions, whose inradius is half
their shorter side, and the trace's samples (one at every triangle crossing, so the sample
where the path enters the deep part is among them), measured with shapely.
"""

from __future__ import annotations

import json
from typing import Any

import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import tlmpc
from tlmpc.abstraction.layout import GOAL_DEPTH_FRACTION, GOAL_DEPTH_TIME, planning_layout
from tlmpc.mission.load import load_mission_text

TOLERANCE = 1e-6


def _mission(
    rects: list[tuple[float, float, float, float]], speed: float = 1.0, **options: Any
) -> dict[str, Any]:
    return {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [20, 0], [20, 12], [0, 12]]},
        "regions": {f"r{k}": {"rect": list(rect)} for k, rect in enumerate(rects)},
        "robot": {"start": [0.5, 0.5], "max_speed": speed},
        "task": [f"visit r{k}" for k in range(len(rects))],
        **({"options": options} if options else {}),
    }


def _depths(compiled: Any, rects: list[tuple[float, float, float, float]]) -> list[float]:
    points = [(x, y) for _, x, y in compiled.artifacts["trace.json"]["points"]]
    depths = []
    for x0, y0, x1, y1 in rects:
        box = shapely.box(x0, y0, x1, y1)
        inside = [p for p in points if box.covers(shapely.Point(p))]
        depths.append(max((box.exterior.distance(shapely.Point(p)) for p in inside), default=-1))
    return depths


#: Rectangles in separate columns of the workspace (so the regions do not overlap).
rectangles = st.lists(
    st.tuples(
        st.floats(0.2, 4.5),  # width
        st.floats(0.2, 10.0),  # height
        st.floats(0.0, 1.0),  # where in its column, across
        st.floats(0.0, 1.0),  # where in its column, up
    ),
    min_size=1,
    max_size=3,
).map(
    lambda drawn: [
        (
            1.0 + 6.0 * k + (5.0 - w) * u,
            1.0 + (10.5 - h) * v,
            1.0 + 6.0 * k + (5.0 - w) * u + w,
            1.0 + (10.5 - h) * v + h,
        )
        for k, (w, h, u, v) in enumerate(drawn)
    ]
)


@pytest.mark.slow
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    rects=rectangles,
    requested=st.one_of(st.none(), st.floats(0.0, 3.0)),
    speed=st.sampled_from([0.5, 1.0, 4.0]),
)
def test_visits_reach_the_goal_depth(
    rects: list[tuple[float, float, float, float]], requested: float | None, speed: float
) -> None:
    options = {} if requested is None else {"goal_depth": requested}
    compiled = tlmpc.compile(_mission(rects, speed, **options))
    for (x0, y0, x1, y1), depth in zip(rects, _depths(compiled, rects), strict=True):
        inradius = min(x1 - x0, y1 - y0) / 2.0
        default = min(GOAL_DEPTH_FRACTION * inradius, GOAL_DEPTH_TIME * speed)
        wanted = default if requested is None else requested
        assert depth >= min(wanted, inradius / 2.0) - TOLERANCE, (depth, wanted, inradius)


@pytest.mark.parametrize(
    ("speed", "depth"),
    # a 10 x 8 room (inradius 4, a quarter of it 1.0): 0.1 s at max_speed, at most 1.0, and
    # at least a thousandth of the workspace's extent (20: 0.02) for a robot crawling
    [(1.0, 0.1), (4.0, 0.4), (20.0, 1.0), (0.001, 0.02)],
)
def test_the_default_depth_is_a_tenth_of_a_second_at_max_speed(speed: float, depth: float) -> None:
    mission = load_mission_text(json.dumps(_mission([(2.0, 2.0, 12.0, 10.0)], speed)))
    layout = planning_layout(mission, 0.0)
    assert layout is not None
    (core,) = layout.regions
    x0, y0, x1, y1 = core.bounds
    for inset in (x0 - 2.0, y0 - 2.0, 12.0 - x1, 10.0 - y1):
        assert depth <= inset <= depth * 1.03


def test_a_body_at_speed_goes_a_tenth_of_a_second_deep() -> None:
    # a body of radius 0.1 at 4 m/s: 0.4 deep, more than the margin (the radius)
    document = _mission([(2.0, 2.0, 12.0, 10.0)], 4.0)
    document["robot"]["radius"] = 0.1
    layout = planning_layout(load_mission_text(json.dumps(document)), 0.1)
    assert layout is not None
    (core,) = layout.regions
    x0, y0, x1, y1 = core.bounds
    for inset in (x0 - 2.0, y0 - 2.0, 12.0 - x1, 10.0 - y1):
        assert 0.4 <= inset <= 0.4 * 1.03


def test_a_margin_deeper_than_the_default_depth_is_kept() -> None:
    # a body of radius 0.3: the margin (the radius by default) is deeper than 0.1 s at 1 m/s
    document = _mission([(2.0, 2.0, 12.0, 10.0)])
    document["robot"]["radius"] = 0.3
    mission = load_mission_text(json.dumps(document))
    layout = planning_layout(mission, 0.3)
    assert layout is not None
    (core,) = layout.regions
    x0, y0, x1, y1 = core.bounds
    for inset in (x0 - 2.0, y0 - 2.0, 12.0 - x1, 10.0 - y1):
        assert 0.3 <= inset <= 0.3 * 1.03


def test_goal_depth_zero_keeps_the_plain_mesh() -> None:
    mission = load_mission_text(json.dumps(_mission([(2.0, 2.0, 6.0, 5.0)], goal_depth=0)))
    assert planning_layout(mission, 0.0) is None
    # at 4 m/s, 0.1 s is 0.4: a quarter of the inradius is the lesser
    fast = _mission([(2.0, 2.0, 6.0, 5.0)], 4.0)
    deep = planning_layout(load_mission_text(json.dumps(fast)), 0.0)
    assert deep is not None
    assert deep.free is None  # a point robot keeps its free space
    (core,) = deep.regions
    # the rectangle 4 x 3 eroded by a quarter of its inradius 1.5: 0.375, and up to 3 % more
    # (the offset that keeps the distance despite the arcs' chords)
    x0, y0, x1, y1 = core.bounds
    for inset in (x0 - 2.0, y0 - 2.0, 6.0 - x1, 5.0 - y1):
        assert 0.375 <= inset <= 0.375 * 1.03


def test_overlapping_goals_fall_back_to_the_margins_depth() -> None:
    # "be in a and b at once": the overlap is a 0.2 m strip along their edges, outside both
    # cores, so no plan reaches the goal depth; a plan at the margin's depth (0) exists
    mission = _mission([(2.0, 2.0, 6.0, 6.0), (5.8, 2.0, 9.8, 6.0)])
    del mission["task"]
    mission["ltl"] = "F (r0 & r1)"
    compiled = tlmpc.compile(mission)
    codes = [d.code for d in compiled.warnings]
    assert "A030" in codes
    points = [(x, y) for _, x, y in compiled.artifacts["trace.json"]["points"]]
    assert any(5.8 <= x <= 6.0 and 2.0 <= y <= 6.0 for x, y in points)
