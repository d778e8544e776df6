"""Rings cut about a corner keep the mesh conforming and observation-preserving, shrink every
edge about the corner by the ring fraction, and cut each trapezoid along its fatter diagonal."""

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
from tlmpc.abstraction.corner import RING_FRACTION, ring_corners
from tlmpc.abstraction.model import Abstraction
from tlmpc.abstraction.touch import _start_cells
from tlmpc.mission.model import Mission


def _star(mesh: Abstraction, vertex: int) -> list[int]:
    return [t for t in range(mesh.num_triangles) if vertex in mesh.triangles[t].tolist()]


def _edges_about(mesh: Abstraction, vertex: int) -> dict[int, float]:
    """Each neighbour w of ``vertex`` and the length of the edge (vertex, w)."""
    found: dict[int, float] = {}
    for t in _star(mesh, vertex):
        for w in mesh.triangles[t].tolist():
            if w != vertex:
                found[w] = math.dist(mesh.vertices[vertex].tolist(), mesh.vertices[w].tolist())
    return found


@settings(deadline=None, max_examples=30)
@given(workspaces(), st.data(), st.integers(1, 3))
def test_rings_keep_the_mesh_conforming_and_shrink_the_edges_about_the_corner(
    mission: Mission, data: st.DataObject, rings: int
) -> None:
    built = build_abstraction(mission)
    picks = data.draw(
        st.lists(st.integers(0, len(built.vertices) - 1), min_size=1, max_size=5, unique=True)
    )
    refined, parents = ring_corners(built, dict.fromkeys(picks, rings), mission.robot.start)
    if refined is built:
        assert parents == []
        return
    _check_mesh(refined, mission)
    area = sum(Polygon(c).area for c in refined.vertices[refined.triangles])
    assert area == pytest.approx(sum(Polygon(c).area for c in built.vertices[built.triangles]))
    # Which corners were cut: those none of whose old neighbours is still one (an independent
    # reading of the result, not the function's own choice).
    starts = {c.triangle for c in _start_cells(built, mission.robot.start)}
    cut = [
        v
        for v in dict.fromkeys(picks)
        if not set(_edges_about(refined, v)) & set(_edges_about(built, v))
    ]
    assert cut, "something was cut"
    for v in cut:
        assert not any(t in starts for t in _star(built, v)), "the start keeps its triangle"
        before = _edges_about(built, v)
        after = _edges_about(refined, v)
        # every edge about the corner is the old one shrunk by fraction ** rings
        assert len(after) == len(before)
        assert sorted(after.values()) == pytest.approx(
            sorted(length * RING_FRACTION**rings for length in before.values()), rel=1e-9
        )
    for a, b in itertools.combinations(cut, 2):
        assert b not in _edges_about(built, a), "no two cut corners share an edge"
    # Each cut star of k triangles gains two pieces per triangle and ring.
    gained = sum(2 * rings * len(_star(built, v)) for v in cut)
    assert refined.num_triangles == built.num_triangles + gained
    assert len(parents) == gained
    # Every piece lies in the triangle it was cut from, and keeps its label and component.
    parent_of = list(range(built.num_triangles)) + parents
    for t in range(refined.num_triangles):
        parent = parent_of[t]
        shape = Polygon(built.vertices[built.triangles[parent]].tolist())
        piece = Polygon(refined.vertices[refined.triangles[t]].tolist())
        assert shape.buffer(1e-9).contains(piece)
        assert refined.letter_of[t] == built.letter_of[parent]
        assert refined.component[t] == built.component[parent]
    # Triangles about no cut corner keep their index and corners.
    touched = {t for v in cut for t in _star(built, v)}
    for t in set(range(built.num_triangles)) - touched:
        assert np.array_equal(refined.triangles[t], built.triangles[t])
    start = Polygon(refined.corners(refined.start).tolist())
    assert start.buffer(1e-9).contains(Point(mission.robot.start))


def _fatness(corners: list[list[float]]) -> float:
    shape = Polygon(corners)
    longest = max(math.dist(a, b) for a, b in itertools.pairwise([*corners, corners[0]]))
    return float(2 * shape.area / longest / longest)


@settings(deadline=None, max_examples=20)
@given(workspaces(), st.data())
def test_each_trapezoid_is_cut_along_its_fatter_diagonal(
    mission: Mission, data: st.DataObject
) -> None:
    """One ring about one corner: for each triangle (c, a, b) about it, the two pieces that
    are not the one about c are the pair, of the two ways to cut the trapezoid
    (p_a, a, b, p_b), whose thinner piece is the fatter (shapely's areas and lengths)."""
    built = build_abstraction(mission)
    vertex = data.draw(st.integers(0, len(built.vertices) - 1))
    refined, parents = ring_corners(built, {vertex: 1}, mission.robot.start)
    if refined is built:
        return
    for parent in _star(built, vertex):
        pieces = [
            refined.vertices[refined.triangles[built.num_triangles + k]].tolist()
            for k, p in enumerate(parents)
            if p == parent
        ]
        assert len(pieces) == 2
        corners = built.triangles[parent].tolist()
        k = corners.index(vertex)
        c, a, b = (built.vertices[corners[(k + i) % 3]] for i in range(3))
        p_a, p_b = c + RING_FRACTION * (a - c), c + RING_FRACTION * (b - c)
        ways = [
            [[p_a, a, b], [p_a, b, p_b]],
            [[p_a, a, p_b], [a, b, p_b]],
        ]
        scores = [min(_fatness([q.tolist() for q in piece]) for piece in way) for way in ways]
        got = min(_fatness(piece) for piece in pieces)
        assert got == pytest.approx(max(scores), rel=1e-9)
        union = shapely.union_all([Polygon(p) for p in pieces])
        assert union.symmetric_difference(Polygon([p_a, a, b, p_b])).area < 1e-9


def test_nothing_to_cut_returns_the_mesh() -> None:
    from tlmpc.mission import load_mission

    mission = load_mission("specs/example1.yaml")
    built = build_abstraction(mission)
    starts = {c.triangle for c in _start_cells(built, mission.robot.start)}
    at_start = built.triangles[min(starts)].tolist()
    assert ring_corners(built, dict.fromkeys(at_start, 2), mission.robot.start) == (built, [])
    assert ring_corners(built, {}, mission.robot.start) == (built, [])
    free = next(v for v in range(len(built.vertices)) if v not in at_start)
    assert ring_corners(built, {free: 0}, mission.robot.start) == (built, [])
