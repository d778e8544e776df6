"""Edge splits where a path touches a triangle keep the mesh conforming and
observation-preserving, and the touch point is the one a brute force finds."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
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
from tlmpc.pipeline.touches import _touch


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
