"""A route's corridor meshed again finer keeps the mesh conforming and observation-preserving:
every piece lies in one old triangle and keeps its label and component, the triangles away
from the corridor are untouched, the route's pieces meet the size asked, and none is thinner
than the floor."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon
from test_abstraction_props import workspaces
from test_refine import _check_mesh

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.corridor import AREA_SHARE, _neighbors, refine_corridor
from tlmpc.abstraction.model import Abstraction, triangle_inradius
from tlmpc.mission.model import Mission


def _wall_length(mesh: Abstraction) -> float:
    """The length of the edges with no triangle across: a hanging point on an edge would make
    both sides of it count."""
    total = 0.0
    for t, side in zip(*np.nonzero(mesh.neighbors < 0), strict=True):
        a, b = mesh.triangles[t, (side + 1) % 3], mesh.triangles[t, (side + 2) % 3]
        total += math.dist(mesh.vertices[a].tolist(), mesh.vertices[b].tolist())
    return total


def _corridor(mesh: Abstraction, route: list[int]) -> set[int]:
    band = {int(n) for t in route for n in mesh.neighbors[t].tolist() if n >= 0}
    return set(route) | band


@settings(deadline=None, max_examples=30)
@given(workspaces(), st.data(), st.floats(0.05, 0.5))
def test_the_corridor_is_meshed_finer_and_the_mesh_stays_conforming(
    mission: Mission, data: st.DataObject, share: float
) -> None:
    built = build_abstraction(mission)
    route = data.draw(
        st.lists(st.integers(0, built.num_triangles - 1), min_size=1, max_size=8, unique=True)
    )
    extent = float(np.ptp(built.vertices, axis=0).max())
    size = share * extent
    floor = data.draw(st.sampled_from([0.0, 0.002 * extent, 0.02 * extent]))
    keep = data.draw(st.lists(st.sampled_from(route), max_size=2, unique=True))
    refined, parents = refine_corridor(
        built, route, mission.robot.start, size=size, floor=floor, keep=keep
    )
    if refined is built:
        assert parents == []
        return
    _check_mesh(refined, mission)
    assert _wall_length(refined) == pytest.approx(_wall_length(built), rel=1e-9)
    old_area = sum(Polygon(c).area for c in built.vertices[built.triangles])
    assert sum(Polygon(c).area for c in refined.vertices[refined.triangles]) == pytest.approx(
        old_area
    )
    assert len(parents) == refined.num_triangles - built.num_triangles
    parent_of = list(range(built.num_triangles)) + parents
    for t in range(refined.num_triangles):
        parent = parent_of[t]
        shape = Polygon(built.vertices[built.triangles[parent]].tolist())
        piece = Polygon(refined.vertices[refined.triangles[t]].tolist())
        assert shape.buffer(1e-9 * extent).contains(piece)
        assert refined.letter_of[t] == built.letter_of[parent]
        assert refined.component[t] == built.component[parent]
        own = triangle_inradius(built.corners(parent))
        assert triangle_inradius(refined.corners(t)) >= min(floor, own) * (1 - 1e-12)
    # away from the corridor, and in the triangles kept whole, nothing changed
    corridor = _corridor(built, route) - set(keep)
    for t in set(range(built.num_triangles)) - corridor:
        assert np.array_equal(refined.corners(t), built.corners(t))
    # the route's pieces are no larger than asked (some may be coarser sizes: at most the
    # last one tried), and a route triangle larger than that was cut
    largest = AREA_SHARE * math.sqrt(3.0) / 4.0 * (size * 2.0**1.5) ** 2
    for t in range(refined.num_triangles):
        if parent_of[t] in route and parent_of[t] not in keep:
            assert Polygon(refined.corners(t).tolist()).area <= largest * (1 + 1e-9)
    start = Polygon(refined.corners(refined.start).tolist())
    assert start.buffer(1e-9 * extent).contains(Point(mission.robot.start))


@settings(deadline=None, max_examples=20)
@given(workspaces(), st.data())
def test_a_floor_no_piece_can_keep_leaves_the_mesh_as_it_was(
    mission: Mission, data: st.DataObject
) -> None:
    built = build_abstraction(mission)
    route = data.draw(
        st.lists(st.integers(0, built.num_triangles - 1), min_size=1, max_size=4, unique=True)
    )
    largest = max(triangle_inradius(built.corners(t)) for t in range(built.num_triangles))
    extent = float(np.ptp(built.vertices, axis=0).max())
    refined, parents = refine_corridor(
        built, route, mission.robot.start, size=0.05 * extent, floor=2.0 * largest
    )
    assert refined is built
    assert parents == []


def test_a_size_above_every_edge_cuts_nothing() -> None:
    from tlmpc.mission import load_mission

    mission = load_mission("specs/example1.yaml")
    built = build_abstraction(mission)
    refined, parents = refine_corridor(
        built, range(built.num_triangles), mission.robot.start, size=100.0, floor=0.0
    )
    assert refined is built
    assert parents == []


def test_the_route_is_cut_to_the_size_asked_on_example_1() -> None:
    """Every edge of a route triangle is cut into pieces no longer than the size, so every
    old vertex keeps its place and the corridor's old edges are unions of new ones."""
    from tlmpc.mission import load_mission

    mission = load_mission("specs/example1.yaml")
    built = build_abstraction(mission)
    route = [built.start, *(int(n) for n in built.neighbors[built.start] if n >= 0)]
    refined, parents = refine_corridor(built, route, mission.robot.start, size=0.5, floor=0.0)
    assert refined is not built
    assert np.array_equal(refined.vertices[: len(built.vertices)], built.vertices)
    edges = shapely.MultiLineString(
        [
            refined.vertices[[a, b]].tolist()
            for row in refined.triangles.tolist()
            for a, b in itertools.combinations(row, 2)
        ]
    )
    for t in route:
        for a, b in itertools.combinations(built.triangles[t].tolist(), 2):
            old = shapely.LineString(built.vertices[[a, b]].tolist())
            pieces = [
                line
                for line in edges.geoms
                if old.buffer(1e-9).contains(line) and line.length > 0.0
            ]
            assert pieces, "the edge is made of new edges"
            assert max(line.length for line in pieces) <= 0.5 + 1e-9
    # and no piece of a route triangle is larger than an equilateral triangle of that edge
    parent_of = list(range(built.num_triangles)) + parents
    bound = AREA_SHARE * math.sqrt(3.0) / 4.0 * 0.5**2
    for t in range(refined.num_triangles):
        if parent_of[t] in route:
            assert Polygon(refined.corners(t).tolist()).area <= bound * (1 + 1e-9)


def test_neighbors_match_a_brute_force_reading() -> None:
    rng = np.random.default_rng(7)
    points = rng.random((30, 2))
    from scipy.spatial import Delaunay

    triangles = Delaunay(points).simplices.astype(np.int64)
    found = _neighbors(triangles)
    for t, row in enumerate(triangles.tolist()):
        for side in range(3):
            edge = {row[(side + 1) % 3], row[(side + 2) % 3]}
            across = [
                u for u, other in enumerate(triangles.tolist()) if u != t and edge <= set(other)
            ]
            assert found[t, side] == (across[0] if across else -1)
