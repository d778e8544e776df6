"""The body's radius exactly: no more, no less.

The configuration space is the free space eroded by the radius exactly (along walls, and
within 2e-5 of it at obstacle corners), plus two steps of the snapping grid.  Oracles are
shapely's exact segment distances on the raw geometry of ``trace.json`` and the doorway's
width as written: a doorway wider than the body by any amount above the grid is open, a
start exactly the radius from a wall is legal, and the path never comes closer than the
radius (to the verifier's stated 1e-9 of the map's size).
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import tlmpc
from tlmpc.base.errors import TlmpcError


def _door(radius: float, door: float, start: tuple[float, float] = (1.0, 3.0)) -> dict[str, Any]:
    """Two rooms of [0, 10] x [0, 6] joined by a door of width ``door`` at x in [4.5, 5.5]."""
    low, high = 3.0 - door / 2.0, 3.0 + door / 2.0
    return {
        "version": 1,
        "workspace": {
            "boundary": {"rect": [0, 0, 10, 6]},
            "holes": [{"rect": [4.5, 0, 5.5, low]}, {"rect": [4.5, high, 5.5, 6]}],
        },
        "regions": {"goal": {"rect": [7, 1, 9, 5]}},
        "robot": {"start": list(start), "radius": radius},
        "options": {"margin": 0},
        "task": ["visit goal"],
    }


def _clearance(trace: dict[str, Any]) -> float:
    """Least exact distance from the trace's segments to the raw obstacles."""
    points = np.asarray(trace["points"], dtype=float)[:, 1:]
    walls = [shapely.Polygon(trace["workspace"]["boundary"]).exterior]
    walls += [shapely.Polygon(h) for h in trace["workspace"]["holes"]]
    segments = [shapely.LineString([a, b]) for a, b in itertools.pairwise(points)]
    return min(float(w.distance(s)) for w in walls for s in segments)


@pytest.mark.parametrize("spare", [0.02, 1e-3])
def test_a_doorway_with_any_room_to_spare_is_open(spare: float) -> None:
    radius = 0.5
    door = 2.0 * radius * (1.0 + spare)
    compiled = tlmpc.compile(_door(radius, door))
    assert not [w for w in compiled.warnings if w.code in ("R002", "R004", "R008")]
    trace = compiled.artifacts["trace.json"]
    assert _clearance(trace) >= radius - 1e-9 * 10.0


def test_a_doorway_narrower_than_the_body_is_named_with_both_widths() -> None:
    mission = _door(0.5, 0.98)
    with pytest.raises(TlmpcError) as failure:
        tlmpc.compile(mission)
    r002 = [d for d in failure.value.diagnostics if d.code == "R002"]
    assert len(r002) == 1
    assert "0.98 wide" in r002[0].message
    assert "the 1 the robot's body needs" in r002[0].message


def test_a_doorway_wider_than_the_body_is_no_r002() -> None:
    """A door 1 wide and a body of diameter 0.98: open, and no passage is reported."""
    compiled = tlmpc.compile(_door(0.49, 1.0))
    assert not [w for w in compiled.warnings if w.code in ("R002", "R004")]
    assert _clearance(compiled.artifacts["trace.json"]) >= 0.49 - 1e-9 * 10.0


@pytest.mark.parametrize(
    "start",
    [(0.5, 3.0), (1.0, 0.5), (0.5, 0.5), (4.0, 1.0), (4.5 - 0.3, 2.0 + 0.4)],
    ids=["left wall", "bottom wall", "room corner", "a hole's face", "a hole's corner"],
)
def test_a_start_exactly_the_radius_from_a_wall_is_legal(start: tuple[float, float]) -> None:
    radius = 0.5
    mission = _door(radius, 2.0, start)
    compiled = tlmpc.compile(mission)
    trace = compiled.artifacts["trace.json"]
    assert trace["points"][0][1:] == list(start)
    assert _clearance(trace) >= radius - 1e-9 * 10.0


@settings(max_examples=max(4, settings().max_examples // 20), deadline=None)
@given(
    st.floats(math.pi / 2, math.pi),
    st.sampled_from([0.0, 1e-12, 1e-10, 3e-10, 1e-9]),
    st.sampled_from([0.0, 0.3]),
)
def test_a_start_the_radius_from_a_corner_in_any_direction_is_legal(
    angle: float, spare: float, margin: float
) -> None:
    """Off the grid, and beside a corner (where the configuration space is round): the start
    must stay in the snapped mesh, and the path keep the radius but for a snapping step."""
    radius = 0.5
    corner = (4.5, 2.0)  # the lower hole's top left corner, the start above and left of it
    away = radius + spare
    start = (corner[0] + away * math.cos(angle), corner[1] + away * math.sin(angle))
    mission = _door(radius, 2.0, start)
    mission["options"] = {"margin": margin}
    compiled = tlmpc.compile(mission)
    trace = compiled.artifacts["trace.json"]
    assert trace["points"][0][1:] == list(start)
    assert _clearance(trace) >= radius - 1e-9 * 10.0


def test_a_start_a_hair_closer_than_the_radius_is_r001() -> None:
    with pytest.raises(TlmpcError) as failure:
        tlmpc.compile(_door(0.5, 2.0, (0.5 - 1e-6, 3.0)))
    assert [d.code for d in failure.value.diagnostics] == ["R001"]


def _obstacle_course() -> Any:
    """A room with a square hole, a triangular hole and a notch in the wall."""
    room = shapely.Polygon([(0, 0), (10, 0), (10, 10), (6, 10), (5, 8), (4, 10), (0, 10)])
    holes = [shapely.box(2, 2, 4, 4), shapely.Polygon([(6, 2), (8, 2.5), (7, 5)])]
    return room.difference(shapely.union_all(holes))


def test_the_exact_reach_holds_every_disc_around_an_obstacle() -> None:
    """Points just inside the radius of every obstacle vertex and edge are in the reach."""
    from tlmpc.mission.cspace import obstacle_reach

    free = _obstacle_course()
    radius = 0.7
    reach = obstacle_reach(free, radius)
    walls = free.boundary
    angles = np.linspace(0.0, 2.0 * math.pi, 720, endpoint=False)
    for x, y in shapely.get_coordinates(walls):
        ring = np.stack(
            [x + 0.999999 * radius * np.cos(angles), y + 0.999999 * radius * np.sin(angles)], axis=1
        )
        inside = shapely.covers(free, shapely.points(ring))
        assert shapely.covers(reach, shapely.points(ring[inside])).all(), (x, y)


@pytest.mark.parametrize("through", [None, (2.0 - 0.7 * 0.6, 2.0 - 0.7 * 0.8)])
def test_erosion_keeps_the_radius_and_loses_little(through: tuple[float, float] | None) -> None:
    """Exact segment distances: at least the radius everywhere, and every point 1.005 r from
    the obstacles kept (0.48 % beyond the radius at corners is all the construction may
    lose); a point exactly the radius from a corner stays in when passed as ``through``."""
    from tlmpc.mission.cspace import erode

    free = _obstacle_course()
    radius = 0.7
    eroded = erode(free, radius, through=through)
    walls = free.boundary
    edges = [
        shapely.LineString(pair)
        for ring in shapely.get_parts(eroded.boundary)
        for pair in itertools.pairwise(shapely.get_coordinates(ring))
    ]
    assert float(np.min(shapely.distance(walls, edges))) >= radius * (1 - 1e-12)
    samples = shapely.points(np.random.default_rng(3).uniform(0, 10, size=(20000, 2)))
    far = shapely.covers(free, samples) & (shapely.distance(walls, samples) >= 1.005 * radius)
    assert shapely.covers(eroded, samples[far]).all()
    if through is not None:
        assert eroded.distance(shapely.Point(through)) <= 1e-12


def test_the_proof_rejects_a_shape_too_close() -> None:
    from tlmpc.mission.cspace import keeps_distance

    free = _obstacle_course()
    assert keeps_distance(free.buffer(-0.7 * 1.0001, quad_segs=64), free, 0.7)
    assert not keeps_distance(free.buffer(-0.7 * 0.999, quad_segs=64), free, 0.7)
    assert not keeps_distance(free.buffer(-0.7, quad_segs=2), free, 0.7)  # chords inside
