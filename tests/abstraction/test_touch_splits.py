"""Edge splits where a path touches a triangle keep the mesh conforming and
observation-preserving, and the touch point is the one a brute force finds."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon
from test_abstraction_props import workspaces
from test_refine import _check_mesh

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.touch import (
    EDGE_MARGIN,
    NEEDLE,
    _start_cells,
    _thin_halves,
    split_edges,
)
from tlmpc.mission.model import Mission
from tlmpc.pipeline.touches import (
    _beside,
    _best_touch,
    _crossing,
    _patch,
    _pieces,
    _pieces_along,
    _touch,
)
from tlmpc.planning.product import STUTTER_COST


@settings(deadline=None, max_examples=30)
@given(workspaces(), st.data())
def test_edge_splits_keep_the_mesh_conforming_and_labels_exact(
    mission: Mission, data: st.DataObject
) -> None:
    built = build_abstraction(mission)
    inner = [
        (t, i)
        for t in range(built.num_triangles)
        for i in range(3)
        if int(built.neighbors[t, i]) >= 0
    ]
    if not inner:
        return
    picks = data.draw(st.lists(st.sampled_from(inner), min_size=1, max_size=6, unique=True))
    fractions = data.draw(st.lists(st.floats(0.0, 1.0), min_size=len(picks), max_size=len(picks)))
    splits = [(t, i, u) for (t, i), u in zip(picks, fractions, strict=True)]
    refined = split_edges(built, splits, mission.robot.start)
    made = int(refined.stats.get("split_for_touches", 0))
    assert refined.num_triangles == built.num_triangles + 2 * made
    assert len(refined.vertices) == len(built.vertices) + made
    _check_mesh(refined, mission)
    area = sum(Polygon(c).area for c in refined.vertices[refined.triangles])
    assert area == pytest.approx(sum(Polygon(c).area for c in built.vertices[built.triangles]))
    # No half is a needle: its smallest height (twice its area over its longest edge) is at
    # least NEEDLE of that edge (shapely's area and lengths).
    for t in range(refined.num_triangles):
        if t < built.num_triangles and np.array_equal(refined.triangles[t], built.triangles[t]):
            continue
        shape = Polygon(refined.vertices[refined.triangles[t]].tolist())
        longest = max(math.dist(a, b) for a, b in itertools.pairwise(list(shape.exterior.coords)))
        assert 2 * shape.area / longest >= NEEDLE * longest * (1 - 1e-9)
    # Every new vertex lies on a split edge, at least EDGE_MARGIN of it from both ends.
    for point in refined.vertices[len(built.vertices) :]:
        assert any(_fraction_on(built, t, i, point) is not None for t, i, _ in splits)
    # Untouched triangles keep their index and corners; the start keeps a triangle holding it.
    cut = {int(c) for c in range(built.num_triangles)} - {
        t
        for t in range(built.num_triangles)
        if not np.array_equal(refined.triangles[t], built.triangles[t])
    }
    assert len(cut) >= built.num_triangles - 2 * made
    start = Polygon(refined.corners(refined.start).tolist())
    assert start.buffer(1e-9).contains(Point(mission.robot.start))


def _fraction_on(mesh: object, t: int, i: int, point: np.ndarray) -> float | None:
    from tlmpc.abstraction.model import Abstraction

    assert isinstance(mesh, Abstraction)
    corners = mesh.triangles[t].tolist()
    a, b = mesh.vertices[corners[(i + 1) % 3]], mesh.vertices[corners[(i + 2) % 3]]
    edge = b - a
    u = float(np.dot(point - a, edge) / np.dot(edge, edge))
    foot = a + u * edge
    if np.linalg.norm(point - foot) > 1e-9 * (1.0 + float(np.linalg.norm(edge))):
        return None
    if not (EDGE_MARGIN - 1e-12 <= u <= 1 - EDGE_MARGIN + 1e-12):
        return None
    return u


@settings(deadline=None, max_examples=20)
@given(workspaces())
def test_a_split_on_a_wall_or_twice_on_one_triangle_is_skipped(mission: Mission) -> None:
    built = build_abstraction(mission)
    walls = [
        (t, i, 0.5)
        for t in range(built.num_triangles)
        for i in range(3)
        if int(built.neighbors[t, i]) < 0
    ]
    assert split_edges(built, walls, mission.robot.start) is built
    inner = [
        (t, i)
        for t in range(built.num_triangles)
        for i in range(3)
        if int(built.neighbors[t, i]) >= 0
    ]
    starts = {c.triangle for c in _start_cells(built, mission.robot.start)}
    free = [
        (t, i)
        for t, i in inner
        if t not in starts
        and int(built.neighbors[t, i]) not in starts
        and not _thin_halves(built, t, i, 0.5, int(built.neighbors[t, i]))
    ]
    if not free:
        return
    t, i = free[0]
    # the same edge named from both sides: one split
    n = int(built.neighbors[t, i])
    j = built.neighbors[n].tolist().index(t)
    once = split_edges(built, [(t, i, 0.5), (n, j, 0.5)], mission.robot.start)
    assert once.stats["split_for_touches"] == 1


points = st.tuples(st.floats(-5, 5), st.floats(0.05, 5))


@settings(deadline=None, max_examples=200)
@given(points, points, st.floats(-3, 3), st.floats(0.1, 4))
def test_the_touch_point_is_the_brute_force_minimum(
    x: tuple[float, float], y: tuple[float, float], left: float, width: float
) -> None:
    """On the edge y = 0 from (left, 0) to (left + width, 0), with x and y above it, the touch
    point minimises |x p| + |p y| as a dense scan of the edge finds it."""
    a, b = (left, 0.0), (left + width, 0.0)
    u = _touch(a, b, x, y)
    assert 0.0 <= u <= 1.0

    def total(v: float) -> float:
        p = (a[0] + v * (b[0] - a[0]), 0.0)
        return math.dist(x, p) + math.dist(p, y)

    scan = min(total(k / 2000) for k in range(2001))
    assert total(u) <= scan + 1e-9 * (1.0 + scan)


# --- the visit touches of the length re-plans (tlmpc.pipeline.touches.visit_touches) ---------

coordinates = st.floats(-20.0, 20.0, allow_nan=False, allow_infinity=False)
points = st.tuples(coordinates, coordinates)


@settings(deadline=None, max_examples=200)
@given(points, points, points, points)
def test_a_segment_crossing_is_where_shapely_finds_it(
    a: tuple[float, float], b: tuple[float, float], c: tuple[float, float], d: tuple[float, float]
) -> None:
    from shapely.geometry import LineString

    first, second = LineString([a, b]), LineString([c, d])
    if first.length < 1e-6 or second.length < 1e-6:
        return
    # away from touching ends and parallel overlaps, where either answer is a rounding
    if min(first.distance(Point(c)), first.distance(Point(d))) < 1e-6:
        return
    if min(second.distance(Point(a)), second.distance(Point(b))) < 1e-6:
        return
    found = _crossing(a, b, c, d)
    meets = first.intersection(second)
    if meets.is_empty:
        assert found is None
        return
    assert meets.geom_type == "Point"
    assert found is not None
    assert found * first.length == pytest.approx(first.project(meets), abs=1e-7)


def _star(mesh: Any, vertex: int) -> list[int]:
    return np.nonzero((mesh.triangles == vertex).any(axis=1))[0].tolist()


@settings(deadline=None, max_examples=40)
@given(workspaces(), st.data())
def test_the_moves_round_a_split_point_weigh_the_path_inside_them(
    mission: Mission, data: st.DataObject
) -> None:
    """The pieces of x -> p -> y in the triangles round a mesh vertex p, summed, are the
    length shapely measures of that path inside them (x and y outside)."""
    from shapely.geometry import LineString
    from shapely.ops import unary_union

    mesh = build_abstraction(mission)
    walls = {
        int(v)
        for t, side in zip(*np.nonzero(mesh.neighbors < 0), strict=True)
        for v in (mesh.triangles[t, (side + 1) % 3], mesh.triangles[t, (side + 2) % 3])
    }
    inner = [v for v in range(len(mesh.vertices)) if v not in walls]
    if not inner:
        event("no vertex off the walls")
        return
    vertex = data.draw(st.sampled_from(inner))
    star = _star(mesh, vertex)
    fan = unary_union([Polygon(mesh.vertices[mesh.triangles[t]]) for t in star])
    p = (float(mesh.vertices[vertex, 0]), float(mesh.vertices[vertex, 1]))
    if not fan.contains(Point(p)):
        event("a vertex on the mesh's boundary")
        return  # a path along a wall has no crossings to weigh
    around = [
        math.atan2(q[1] - p[1], q[0] - p[0])
        for t in star
        for q in mesh.vertices[mesh.triangles[t]].tolist()
        if tuple(q) != p
    ]
    angle = st.floats(0.0, 2.0 * math.pi)
    ends = []
    for _ in range(2):
        theta = data.draw(angle)
        if any(abs(math.sin(theta - a)) < 1e-3 for a in around):
            event("along an edge through the vertex")
            return
        radius = 1.5 * math.dist(*fan.envelope.exterior.coords[:3:2]) + 1.0
        ends.append((p[0] + radius * math.cos(theta), p[1] + radius * math.sin(theta)))
    x, y = ends
    if math.dist(x, y) < 1e-3:
        return
    path = _beside(p, x, y)
    if path is None:
        return
    assert math.dist(path[1], p) <= 1e-6 * min(math.dist(x, p), math.dist(p, y)) * (1 + 1e-9)
    pieces = _pieces_along(mesh, vertex, path)
    assert pieces == _pieces(mesh, vertex, x, y)
    inside = LineString(path).intersection(fan).length
    event("weighed")
    assert sum(pieces.values()) - len(pieces) * STUTTER_COST == pytest.approx(inside, abs=1e-9)
    triangles = {tuple(int(v) for v in mesh.triangles[t]) for t in star}
    assert {corners for corners, _, _ in pieces} <= triangles
    assert all(entry != exit and entry < 3 for _, entry, exit in pieces)


@settings(deadline=None, max_examples=40)
@given(workspaces(), st.data())
def test_the_touch_chosen_is_the_shortest_over_every_outward_edge(
    mission: Mission, data: st.DataObject
) -> None:
    """Against a brute force (every edge of the patch facing another letter, x and y across
    it from its triangle, 401 points along its inner 60 %): the chosen touch is no longer
    than any of them, and its length is x -> p -> y."""
    mesh = build_abstraction(mission)
    start = data.draw(st.integers(0, mesh.num_triangles - 1))
    patch = _patch(mesh, [start])
    low, high = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    xs = st.floats(float(low[0]), float(high[0]))
    ys = st.floats(float(low[1]), float(high[1]))
    x = (data.draw(xs), data.draw(ys))
    y = (data.draw(xs), data.draw(ys))
    chosen = _best_touch(mesh, patch, x, y)
    brute = math.inf
    letter = int(mesh.letter_of[start])
    for t in patch:
        corners = mesh.vertices[mesh.triangles[t]]
        for edge in range(3):
            n = int(mesh.neighbors[t, edge])
            if n < 0 or int(mesh.letter_of[n]) == letter:
                continue
            a, b = corners[(edge + 1) % 3], corners[(edge + 2) % 3]
            normal = np.array([a[1] - b[1], b[0] - a[0]])
            if normal @ (corners[edge] - a) > 0:
                normal = -normal  # pointing away from the triangle
            if normal @ (np.asarray(x) - a) <= 0 or normal @ (np.asarray(y) - a) <= 0:
                continue
            for u in np.linspace(EDGE_MARGIN, 1.0 - EDGE_MARGIN, 401):
                q = a + u * (b - a)
                brute = min(brute, math.dist(x, q) + math.dist(q, y))
    if chosen is None:
        event("no edge faces both ends")
        assert brute == math.inf
        return
    event("a touch")
    length, t, edge, u = chosen
    assert length <= brute + 1e-9
    assert brute <= length * (1.0 + 1e-4) + 1e-9  # (the brute force's grid)
    corners = mesh.vertices[mesh.triangles[t]]
    a, b = corners[(edge + 1) % 3], corners[(edge + 2) % 3]
    q = a + u * (b - a)
    assert length == pytest.approx(math.dist(x, q) + math.dist(q, y))
