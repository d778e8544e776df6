"""A robot with a body: the body never meets an obstacle, narrow passages are named, margins.

Every claim is checked with shapely on the compiled ``trace.json`` alone: the distance from
each straight segment of the trace to every hole and to the boundary ring, against the
radius; depth into a goal as the distance of trace samples to the goal's boundary.  The
configuration space the oracle needs (to know when a plan must exist) is computed here with
shapely's own buffer, not with tlmpc's.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import tlmpc
from tlmpc.base.errors import InvalidInputError, NoPlanError, TlmpcError
from tlmpc.mission.body import ARC_SEGMENTS, body_radius, conservative_offset
from tlmpc.mission.load import check_text
from tlmpc.mission.model import Robot

Mission = dict[str, Any]


def _door(radius: float, *, margin: float | None = None, door: float = 1.0) -> Mission:
    """Two rooms joined by a door of width ``door`` at x in [4.5, 5.5], around y = 3."""
    low, high = 3.0 - door / 2.0, 3.0 + door / 2.0
    mission: Mission = {
        "version": 1,
        "workspace": {
            "boundary": {"rect": [0, 0, 10, 6]},
            "holes": [{"rect": [4.5, 0, 5.5, low]}, {"rect": [4.5, high, 5.5, 6]}],
        },
        "regions": {"goal": {"rect": [7, 1, 9, 5]}, "bad": {"rect": [2, 4, 3, 5]}},
        "robot": {"start": [1, 3], "radius": radius},
        "task": ["visit goal", "avoid bad"],
    }
    if margin is not None:
        mission["options"] = {"margin": margin}
    return mission


def _segments(trace: dict[str, Any]) -> list[Any]:
    points = np.asarray(trace["points"], dtype=float)[:, 1:]
    if len(points) == 1:
        return [shapely.Point(points[0])]
    return [shapely.LineString([a, b]) for a, b in itertools.pairwise(points)]


def _body_clearance(mission: Mission, trace: dict[str, Any]) -> float:
    """Least distance from the trace's segments to the obstacles, minus nothing (raw)."""
    boundary = shapely.Polygon(trace["workspace"]["boundary"])
    holes = [shapely.Polygon(h) for h in trace["workspace"]["holes"]]
    least = math.inf
    for segment in _segments(trace):
        assert boundary.covers(segment), "the reference point left the workspace"
        least = min(least, boundary.exterior.distance(segment))
        for hole in holes:
            least = min(least, hole.distance(segment))
    return least


def _codes(error: TlmpcError) -> list[str]:
    return [d.code for d in error.diagnostics]


def test_body_radius_of_a_footprint_is_its_circumscribed_radius() -> None:
    footprint = ((-0.3, -0.2), (0.4, -0.2), (0.4, 0.25), (-0.3, 0.25))
    corners = np.asarray(footprint)
    assert body_radius(Robot(start=(0, 0), footprint=footprint)) == pytest.approx(
        float(np.max(np.hypot(corners[:, 0], corners[:, 1])))
    )
    assert body_radius(Robot(start=(0, 0), radius=0.7, footprint=footprint)) == 0.7
    assert body_radius(Robot(start=(0, 0))) == 0.0


def test_body_keeps_its_radius_through_a_door() -> None:
    mission = _door(0.3, margin=0.0)
    compiled = tlmpc.compile(mission)
    trace = compiled.artifacts["trace.json"]
    assert trace["radius"] == 0.3
    assert _body_clearance(mission, trace) >= 0.3
    assert tlmpc.verify_trace(trace).satisfied  # the verifier checks the body too


def test_a_door_narrower_than_the_robot_is_named() -> None:
    with pytest.raises(NoPlanError) as caught:
        tlmpc.compile(_door(0.6))
    codes = _codes(caught.value)
    assert "R002" in codes
    assert "R004" in codes
    pinch = next(d for d in caught.value.diagnostics if d.code == "R002")
    assert "1 wide" in pinch.message
    assert "hole 1 and hole 2" in pinch.message
    x, y = (float(v) for v in pinch.message.split(" at (")[1].split(")")[0].split(","))
    assert 4.5 <= x <= 5.5
    assert 2.5 <= y <= 3.5


def test_a_blocked_shortcut_beside_an_open_way_is_not_a_split() -> None:
    # a slit 0.4 wide in a wall, and an open way 3 wide around the wall's end
    mission: Mission = {
        "version": 1,
        "workspace": {
            "boundary": {"rect": [0, 0, 10, 10]},
            "holes": [{"rect": [4.5, 0, 5.5, 4.8]}, {"rect": [4.5, 5.2, 5.5, 7]}],
        },
        "regions": {"goal": {"rect": [7, 1, 9, 3]}},
        "robot": {"start": [1, 1], "radius": 0.3},
        "task": ["visit goal"],
        "options": {"margin": 0},
    }
    compiled = tlmpc.compile(mission)
    assert not [w for w in compiled.warnings if w.code == "R002"]
    assert _body_clearance(mission, compiled.artifacts["trace.json"]) >= 0.3


def test_start_inside_the_inflated_obstacles_is_an_error() -> None:
    mission = _door(0.3)
    mission["robot"]["start"] = [4.3, 1.0]  # 0.2 from hole 1
    with pytest.raises(InvalidInputError) as caught:
        tlmpc.compile(mission)
    assert _codes(caught.value) == ["R001"]
    assert "hole 1" in caught.value.diagnostics[0].message


def test_region_within_the_radius_of_obstacles_vanishes_with_a_warning() -> None:
    mission = _door(0.3, margin=0.0)
    mission["regions"]["corner"] = {"rect": [9.8, 5.8, 10, 6]}
    mission["task"] = ["visit goal"]
    compiled = tlmpc.compile(mission)
    assert [w.code for w in compiled.warnings if w.code.startswith("R")] == ["R003"]


def test_inflate_is_an_alias_of_radius_and_must_agree() -> None:
    text = (
        "version: 1\nworkspace: {map: m.yaml, inflate: 0.2}\nregions: {a: {rect: [0,0,1,1]}}\n"
        "robot: {start: [0.5, 0.5], radius: 0.3}\ntask: [visit a]\n"
    )
    codes = [d.code for d in check_text(text, "m.yaml")]
    assert "R005" in codes


def test_margin_is_kept_where_the_door_allows_it() -> None:
    radius, margin = 0.3, 0.15
    mission = _door(radius, margin=margin)
    compiled = tlmpc.compile(mission)
    trace = compiled.artifacts["trace.json"]
    # independent: the doorway (1.0) is wider than 2 (radius + margin) = 0.9
    assert _body_clearance(mission, trace) - radius >= margin
    bad = shapely.Polygon([(2, 4), (3, 4), (3, 5), (2, 5)])
    assert min(bad.distance(s) for s in _segments(trace)) >= margin
    goal = shapely.Polygon([(7, 1), (9, 1), (9, 5), (7, 5)])
    samples = shapely.points(np.asarray(trace["points"])[:, 1:])
    depth = max(goal.boundary.distance(p) for p in samples if goal.covers(p))
    assert depth >= margin
    summary = compiled.summary["clearance"]
    assert summary["margin"] == margin
    assert summary["radius"] == radius
    assert summary["obstacles"] >= margin
    assert summary["depth"]["goal"]["achieved"] >= margin
    assert not [w for w in compiled.warnings if w.code in ("R006", "R007", "R008")]


def test_margin_the_door_cannot_give_is_a_warning_and_still_a_plan() -> None:
    radius, margin = 0.3, 0.3  # the doorway is 1.0 < 2 (radius + margin)
    mission = _door(radius, margin=margin)
    compiled = tlmpc.compile(mission)
    codes = [w.code for w in compiled.warnings]
    assert "R008" in codes
    assert "R006" in codes
    trace = compiled.artifacts["trace.json"]
    assert _body_clearance(mission, trace) >= radius  # the body is still kept off
    near = next(w for w in compiled.warnings if w.code == "R006")
    x = float(near.message.split("near (")[1].split(",")[0])
    assert 4.0 <= x <= 6.0  # at the door


def test_small_goal_is_reached_at_its_middle() -> None:
    mission = _door(0.2, margin=0.5)
    mission["regions"]["goal"] = {"rect": [7.5, 2.8, 7.9, 3.2]}  # inradius 0.2 < margin
    compiled = tlmpc.compile(mission)
    trace = compiled.artifacts["trace.json"]
    goal = shapely.Polygon([(7.5, 2.8), (7.9, 2.8), (7.9, 3.2), (7.5, 3.2)])
    samples = shapely.points(np.asarray(trace["points"])[:, 1:])
    depth = max(goal.boundary.distance(p) for p in samples if goal.covers(p))
    assert depth >= 0.1  # half the inradius at least
    assert not [w for w in compiled.warnings if w.code == "R007"]


def test_verifier_checks_the_body_against_obstacles() -> None:
    trace = {
        "format": "tlmpc.trace/1",
        "ltl": "F a",
        "regions": {"a": [[8, 0], [10, 0], [10, 2], [8, 2]]},
        "workspace": {
            "boundary": [[0, 0], [10, 0], [10, 10], [0, 10]],
            "holes": [[[4, 2], [6, 2], [6, 4], [4, 4]]],
        },
        "points": [[0, 1, 1.5], [1, 9, 1.5]],  # passes 0.5 below the hole
        "loop_start": None,
        "end": "stay",
    }
    assert tlmpc.verify_trace({**trace, "radius": 0.4}).satisfied
    verdict = tlmpc.verify_trace({**trace, "radius": 0.6})
    assert not verdict.satisfied
    assert verdict.robustness < 0


def test_the_first_workspace_violation_is_the_bodys_first_contact() -> None:
    # the body (0.5) reaches the outer wall y = 0 at t = 1.5 / 1.8 s, then the point enters the
    # hole at t = 2 + 2/3 s: the contact comes first, though the path only leaves later
    trace = {
        "format": "tlmpc.trace/1",
        "ltl": "F a",
        "regions": {"a": [[8, 8], [9, 8], [9, 9], [8, 9]]},
        "workspace": {
            "boundary": [[0, 0], [10, 0], [10, 10], [0, 10]],
            "holes": [[[4, 4], [6, 4], [6, 6], [4, 6]]],
        },
        "points": [[0, 2, 2], [1, 2, 0.2], [2, 2, 2], [3, 5, 5], [4, 2, 2]],
        "loop_start": None,
        "end": "stay",
        "radius": 0.5,
    }
    verdict = tlmpc.verify_trace(trace)
    first = verdict.workspace_violation
    assert first is not None
    assert first.time is not None
    assert first.position is not None
    assert first.time == pytest.approx(1.5 / 1.8, abs=1e-6)
    assert first.position == pytest.approx((2.0, 0.5), abs=1e-6)
    assert "body" in first.message
    entries = [v for v in verdict.violations if v.conjunct == "workspace"]
    assert [round(v.time or 0.0, 6) for v in entries] == [round(1.5 / 1.8, 6), round(8 / 3, 6)]


@st.composite
def _rooms(draw: st.DrawFn) -> tuple[Mission, float]:
    radius = draw(st.floats(0.05, 0.6))
    holes = []
    for _ in range(draw(st.integers(1, 5))):
        x = draw(st.floats(0.5, 8.0))
        y = draw(st.floats(0.5, 8.0))
        w = draw(st.floats(0.2, 2.0))
        h = draw(st.floats(0.2, 2.0))
        holes.append([x, y, x + w, y + h])
    return (
        {
            "version": 1,
            "workspace": {
                "boundary": {"rect": [0, 0, 10, 10]},
                "holes": [{"rect": h} for h in holes],
            },
            "regions": {},
            "robot": {"start": [0, 0], "radius": radius},
            "task": ["visit goal"],
            "options": {"margin": draw(st.sampled_from([0.0, 0.1]))},
        },
        radius,
    )


@pytest.mark.slow
@given(_rooms(), st.integers(0, 10**6))
def test_body_never_meets_an_obstacle(case: tuple[Mission, float], seed: int) -> None:
    mission, radius = case
    boundary = shapely.box(0, 0, 10, 10)
    free = boundary.difference(
        shapely.union_all([shapely.box(*h["rect"]) for h in mission["workspace"]["holes"]])
    )
    # the oracle's own configuration space, a little smaller than the planner's
    room = free.buffer(-radius * 1.1, quad_segs=16)
    parts = [p for p in shapely.get_parts(room) if p.area > 0.05]
    assume(parts)
    rng = np.random.default_rng(seed)
    home = parts[int(rng.integers(len(parts)))]
    start = home.representative_point()
    target = home.buffer(-0.05).representative_point() if home.area > 0.5 else start
    assume(not home.buffer(-0.05).is_empty)
    mission["robot"]["start"] = [start.x, start.y]
    mission["regions"]["goal"] = {
        "rect": [target.x - 0.05, target.y - 0.05, target.x + 0.05, target.y + 0.05]
    }
    compiled = tlmpc.compile(mission)  # a plan must exist: the goal is in the start's part
    trace = compiled.artifacts["trace.json"]
    assert _body_clearance(mission, trace) >= radius * (1 - 1e-9)
    assert tlmpc.verify_trace(trace).satisfied


def test_margin_from_an_avoided_region_in_the_way() -> None:
    margin = 1.2
    mission: Mission = {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, 12, 8]}},
        "regions": {"goal": {"rect": [8, 1.5, 10, 3.5]}, "bad": {"rect": [4, 0, 6, 3]}},
        "robot": {"start": [1.5, 1.5]},
        "task": ["visit goal", "avoid bad"],
        "options": {"margin": margin},
    }
    compiled = tlmpc.compile(mission)
    trace = compiled.artifacts["trace.json"]
    bad = shapely.box(4, 0, 6, 3)
    assert min(bad.distance(s) for s in _segments(trace)) >= margin
    assert compiled.summary["clearance"]["forbidden"]["bad"] >= margin
    assert not [w for w in compiled.warnings if w.code.startswith("R")]
    # without a margin the shortest way passes closer
    mission["options"] = {"margin": 0}
    plain = tlmpc.compile(mission).artifacts["trace.json"]
    assert min(bad.distance(s) for s in _segments(plain)) < margin


@st.composite
def _obstacles(draw: st.DrawFn) -> tuple[list[list[tuple[float, float]]], float]:
    """Random convex and non-convex holes (rectangles, triangles, L shapes) and a radius."""
    holes: list[list[tuple[float, float]]] = []
    for _ in range(draw(st.integers(1, 4))):
        x = draw(st.floats(1.0, 7.0))
        y = draw(st.floats(1.0, 7.0))
        w = draw(st.floats(0.3, 2.0))
        h = draw(st.floats(0.3, 2.0))
        kind = draw(st.sampled_from(["rect", "triangle", "L"]))
        if kind == "rect":
            holes.append([(x, y), (x + w, y), (x + w, y + h), (x, y + h)])
        elif kind == "triangle":
            holes.append([(x, y), (x + w, y + h / 3), (x + w / 4, y + h)])
        else:
            holes.append(
                [
                    (x, y),
                    (x + w, y),
                    (x + w, y + h / 3),
                    (x + w / 3, y + h / 3),
                    (x + w / 3, y + h),
                    (x, y + h),
                ]
            )
    return holes, draw(st.floats(0.02, 0.8))


@pytest.mark.slow
@given(_obstacles())
def test_every_triangle_keeps_the_radius_from_every_obstacle(
    case: tuple[list[list[tuple[float, float]]], float],
) -> None:
    from tlmpc.abstraction.build import build_abstraction
    from tlmpc.abstraction.layout import planning_layout
    from tlmpc.ltl.parser import parse_ltl
    from tlmpc.mission.model import Mission as MissionModel
    from tlmpc.mission.model import Options, Region, Workspace

    holes, radius = case
    union = shapely.union_all([shapely.Polygon(h) for h in holes])
    assume(union.geom_type == "Polygon" and not union.interiors)  # overlapping holes merge
    boundary = ((0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0))
    free = shapely.Polygon(boundary).difference(union)
    room = free.buffer(-1.2 * radius)
    assume(not room.is_empty)
    start = room.representative_point()
    mission = MissionModel(
        name="m",
        workspace=Workspace(boundary=boundary, holes=(tuple(union.exterior.coords[:-1]),)),
        regions=(Region(name="a", polygon=((0.0, 0.0), (1.0, 0.0), (1.0, 1.0))),),
        robot=Robot(start=(start.x, start.y), radius=radius),
        formula=parse_ltl("F a"),
        options=Options(margin=0.0),
    )
    abstraction = build_abstraction(mission, planning_layout(mission, 0.0))
    corners = abstraction.vertices[abstraction.triangles]
    triangles = shapely.polygons(np.concatenate([corners, corners[:, :1]], axis=1))
    walls = shapely.union(shapely.Polygon(boundary).exterior, union)
    least = float(np.min(shapely.distance(walls, triangles)))
    assert least >= radius * (1 - 1e-9)
    # and the configuration space is not needlessly small: it holds every point 1.05 r away
    assert shapely.union_all(triangles).buffer(1e-9).covers(free.buffer(-1.05 * radius))


@pytest.mark.slow
@settings(max_examples=max(8, settings().max_examples * 3 // 20))  # a compile per example
@given(
    st.floats(2.0, 7.0),  # x of the wall
    st.floats(0.5, 0.9),  # thickness of the wall
    st.floats(1.0, 8.0),  # bottom of the gap
    st.floats(0.1, 1.0),  # width of the gap
    st.floats(0.5, 2.0),  # body diameter / gap width
)
def test_a_gap_narrower_than_the_body_is_named_where_it_is(
    x: float, thickness: float, low: float, gap: float, ratio: float
) -> None:
    radius = ratio * gap / 2.0
    assume(abs(ratio - 1.0) > 0.1)  # clear of the conservative offset's few percent
    mission: Mission = {
        "version": 1,
        "workspace": {
            "boundary": {"rect": [0, 0, 10, 10]},
            "holes": [
                {"rect": [x, 0, x + thickness, low]},
                {"rect": [x, low + gap, x + thickness, 10]},
            ],
        },
        "regions": {"goal": {"rect": [9.0, 4.5, 9.8, 5.5]}},
        "robot": {"start": [x / 2.0, 5.0], "radius": radius},
        "task": ["visit goal"],
        "options": {"margin": 0},
    }
    assume(x / 2.0 >= 1.1 * radius and 9.0 - (x + thickness) > 2.2 * radius)
    if ratio < 1.0:  # the body fits through
        compiled = tlmpc.compile(mission)
        assert not [w for w in compiled.warnings if w.code.startswith("R")]
        assert _body_clearance(mission, compiled.artifacts["trace.json"]) >= radius * (1 - 1e-9)
        return
    with pytest.raises(NoPlanError) as caught:
        tlmpc.compile(mission)
    pinches = [d for d in caught.value.diagnostics if d.code == "R002"]
    assert len(pinches) == 1
    message = pinches[0].message
    width = float(message.split("a passage ")[1].split(" wide")[0])
    assert width == pytest.approx(gap, rel=1e-3)
    px, py = (float(v) for v in message.split(" at (")[1].split(")")[0].split(","))
    assert x - 1e-4 <= px <= x + thickness + 1e-4  # the message rounds to 6 digits
    assert low - 1e-4 <= py <= low + gap + 1e-4
    assert "hole 1 and hole 2" in message
    assert "R004" in _codes(caught.value)


def test_polarity_of_propositions() -> None:
    from tlmpc.ltl.parser import parse_ltl
    from tlmpc.ltl.polarity import polarities

    assert polarities(parse_ltl("F a & G !b")) == {"a": "positive", "b": "negative"}
    assert polarities(parse_ltl("!(a -> F b)")) == {"a": "positive", "b": "negative"}
    assert polarities(parse_ltl("a <-> b")) == {"a": "both", "b": "both"}
    assert polarities(parse_ltl("!b U a")) == {"a": "positive", "b": "negative"}
    assert polarities(parse_ltl("G(a -> F c) & !(b R c)")) == {
        "a": "negative",
        "b": "negative",
        "c": "both",
    }


def test_check_reports_the_body_diagnostics(tmp_path: Path) -> None:
    import subprocess
    import sys

    import yaml

    narrow = tmp_path / "narrow.yaml"
    narrow.write_text(yaml.safe_dump(_door(0.6)))
    start = _door(0.3)
    start["robot"]["start"] = [4.3, 1.0]
    close = tmp_path / "close.yaml"
    close.write_text(yaml.safe_dump(start))
    done = subprocess.run(
        [sys.executable, "-m", "tlmpc", "check", str(narrow), str(close)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 1
    assert "warning[R002]" in done.stderr
    assert f"{close}:" in done.stderr
    assert "error[R001]" in done.stderr
    assert "1 of 2 mission file(s) valid" in done.stderr


@settings(  # a compile per example; many random layouts have no deep way to the goal
    max_examples=max(10, settings().max_examples // 5),
    suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow],
)
@given(_rooms(), st.floats(0.05, 0.5), st.integers(0, 10**6))
def test_margin_is_kept_where_the_geometry_allows(
    case: tuple[Mission, float], margin: float, seed: int
) -> None:
    mission, radius = case
    mission["options"] = {"margin": margin}
    boundary = shapely.box(0, 0, 10, 10)
    free = boundary.difference(
        shapely.union_all([shapely.box(*h["rect"]) for h in mission["workspace"]["holes"]])
    )
    deep = free.buffer(-1.1 * (radius + margin), quad_segs=16)  # the oracle's own offset
    parts = [p for p in shapely.get_parts(deep) if p.area > 0.05]
    assume(parts)
    rng = np.random.default_rng(seed)
    home = parts[int(rng.integers(len(parts)))]
    start = home.representative_point()
    corner = shapely.get_coordinates(home.exterior)[int(rng.integers(len(home.exterior.coords)))]
    size = float(rng.uniform(0.3, 1.5))
    goal = shapely.box(corner[0] - size, corner[1] - size, corner[0] + size, corner[1] + size)
    assume(free.covers(goal))
    mission["robot"]["start"] = [start.x, start.y]
    mission["regions"]["goal"] = {"rect": list(goal.bounds)}
    compiled = tlmpc.compile(mission)
    codes = {w.code for w in compiled.warnings}
    trace = compiled.artifacts["trace.json"]
    clearance = _body_clearance(mission, trace) - radius
    samples = shapely.points(np.asarray(trace["points"])[:, 1:])
    depth = max(goal.boundary.distance(p) for p in samples if goal.covers(p))
    inradius = size  # a square of side 2 * size
    wanted = min(margin, inradius / 2)
    # independent: the goal's core is in the start's part of the deep free space
    core = goal.buffer(-1.1 * wanted, quad_segs=16)
    if home.intersection(core).area > 0.0:
        assert "R008" not in codes
        assert clearance >= margin * (1 - 1e-9)
        assert depth >= wanted * (1 - 1e-9)
    # the warnings say exactly when the margin or the depth was not reached
    assert ("R006" in codes) == (clearance < margin * (1 - 1e-9))
    assert ("R007" in codes) == (depth < wanted * (1 - 1e-9))
    assert _body_clearance(mission, trace) >= radius * (1 - 1e-9)


@given(
    corners=st.lists(st.tuples(st.floats(-5.0, 5.0), st.floats(-5.0, 5.0)), min_size=3, max_size=7),
    distance=st.floats(0.01, 2.0),
    grow=st.booleans(),
)
def test_a_conservative_offset_keeps_the_whole_distance_despite_the_chords(
    corners: list[tuple[float, float]], distance: float, grow: bool
) -> None:
    """Shapely draws an offset's arcs as chords, whose middles dip towards the shape: buffered
    (or eroded) by :func:`conservative_offset`, every point of the result's boundary, a
    chord's middle included, is at least the distance from the shape's boundary."""
    shape = shapely.convex_hull(shapely.MultiPoint(corners))
    assume(isinstance(shape, shapely.Polygon) and shape.area > 0.5)
    reach = conservative_offset(distance)
    offset = shape.buffer(reach if grow else -reach, quad_segs=ARC_SEGMENTS)
    assume(not offset.is_empty)
    boundary = shapely.segmentize(offset.boundary, distance / 50.0)
    points = shapely.points(shapely.get_coordinates(boundary))
    nearest = float(shapely.distance(shape.boundary, points).min())
    assert nearest >= distance * (1.0 - 1e-9), (nearest, distance)
