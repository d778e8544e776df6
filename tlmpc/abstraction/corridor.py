"""Refinement along a route: the triangles a plan crosses, meshed again finer.

A field follows its piece of the path only as closely as its triangle allows: the portal
insets and the reach of an affine field near a portal's end are fractions of the portal, and
off its piece the flow of a large triangle comes back to it slowly.  Here the route's
triangles are meshed again into triangles of edges about ``size``:

* the **corridor** is the route's triangles and the triangles next to them (a band that
  grades the fine triangles into the mesh round it);
* every edge inside the corridor with a route triangle on one side, and every wall edge of a
  route triangle, is cut into equal pieces no longer than ``size``; the edges between the
  corridor and the rest of the mesh are kept whole, so the mesh stays conforming;
* Triangle meshes the corridor with every old edge a constraint segment and no point added on
  any segment (so each new triangle lies inside one old triangle, whose label and component it
  keeps), its route triangles no larger than an equilateral triangle of edge ``size``, and all
  of it with angles of at least :data:`MIN_ANGLE` where the kept edges allow.

Each old triangle keeps its index for its first piece; the others are appended, the new points
too.  No piece is made whose inradius is below ``floor``: the route is then left as it was.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Collection

import numpy as np
import shapely

from tlmpc.abstraction.model import Abstraction, FloatArray, triangle_inradius
from tlmpc.abstraction.refine import with_splits
from tlmpc.abstraction.triangulate import triangulate_in_frame

#: Triangle's quality bound inside the corridor (degrees).
MIN_ANGLE = 25.0
#: The route's triangles are at most this many times the area of an equilateral triangle of
#: edge ``size`` (Triangle's area bound; its quality triangles are then about that wide).
AREA_SHARE = 1.0
#: A corridor's Steiner points are at most this many per triangle it holds (quality meshing
#: beside a kept edge at a sharp input angle would otherwise run on).
STEINER_PER_TRIANGLE = 64


def refine_corridor(
    abstraction: Abstraction,
    route: Collection[int],
    start_point: tuple[float, float],
    *,
    size: float,
    floor: float,
    keep: Collection[int] = (),
) -> tuple[Abstraction, list[int]]:
    """:func:`_refine_once` at ``size``, or at the first of :data:`COARSER` larger sizes whose
    pieces all keep an inradius of at least ``floor``."""
    for attempt in range(COARSER + 1):
        refined, parents = _refine_once(
            abstraction, route, start_point, size=size * GROWTH**attempt, floor=floor, keep=keep
        )
        if refined is not abstraction:
            return refined, parents
    return abstraction, []


#: Sizes tried after the first, each this many times the one before.
COARSER = 3
GROWTH = math.sqrt(2.0)


def _refine_once(
    abstraction: Abstraction,
    route: Collection[int],
    start_point: tuple[float, float],
    *,
    size: float,
    floor: float,
    keep: Collection[int] = (),
) -> tuple[Abstraction, list[int]]:
    """``abstraction`` with the corridor of ``route`` (triangle ids) meshed again finer (see
    the module doc), ``keep`` left whole (and out of the corridor), and the triangle of
    ``abstraction`` each appended triangle lies in;
    ``abstraction`` itself and ``[]`` when no edge needs a cut or a piece would have an
    inradius below ``floor`` (and below its triangle's own)."""
    tri = abstraction.triangles
    nbr = abstraction.neighbors
    points = abstraction.vertices
    on_route = np.zeros(abstraction.num_triangles, dtype=bool)
    on_route[sorted(route)] = True
    band = nbr[on_route].ravel()
    in_corridor = on_route.copy()
    in_corridor[band[band >= 0]] = True
    kept = sorted(keep)
    on_route[kept] = False
    in_corridor[kept] = False
    corridor = np.flatnonzero(in_corridor).tolist()
    # every edge of the corridor once: (low, high) vertex ids -> cut into this many pieces
    pieces: dict[tuple[int, int], int] = {}
    holes: list[FloatArray] = []
    for t in corridor:
        for side in range(3):
            a, b = int(tri[t, (side + 1) % 3]), int(tri[t, (side + 2) % 3])
            key = (min(a, b), max(a, b))
            there = int(nbr[t, side])
            if there >= 0 and not in_corridor[there]:
                pieces[key] = 1  # shared with the mesh round the corridor: kept whole
                holes.append(points[tri[there]].mean(axis=0))
                continue
            cut = on_route[t] or (there >= 0 and on_route[there])
            length = float(np.hypot(*(points[b] - points[a])))
            count = max(1, math.ceil(length / size)) if cut else 1
            pieces[key] = max(pieces.get(key, 1), count)
            if there < 0:  # a wall: a point just outside it, should the corridor enclose it
                holes.append(_outside(points[tri[t]], side))
    if all(count == 1 for count in pieces.values()):
        return abstraction, []
    old_ids = sorted({int(v) for t in corridor for v in tri[t].tolist()})
    local = {v: k for k, v in enumerate(old_ids)}
    coordinates: list[FloatArray] = [points[v] for v in old_ids]
    segments: list[tuple[int, int]] = []
    for (a, b), count in sorted(pieces.items()):
        chain = [local[a]]
        for k in range(1, count):
            chain.append(len(coordinates))
            coordinates.append(points[a] + (k / count) * (points[b] - points[a]))
        chain.append(local[b])
        segments.extend(itertools.pairwise(chain))
    equilateral = math.sqrt(3.0) / 4.0 * size * size
    regions = [
        (*points[tri[t]].mean(axis=0).tolist(), index + 1, AREA_SHARE * equilateral)
        if on_route[t]
        else (*points[tri[t]].mean(axis=0).tolist(), index + 1, -1.0)
        for index, t in enumerate(corridor)
    ]
    given = np.asarray(coordinates, dtype=np.float64)
    data: dict[str, object] = {
        "vertices": given,
        "segments": np.asarray(segments, dtype=np.int64),
        "regions": np.asarray(regions, dtype=np.float64),
    }
    # Triangle eats the triangles outside the segments from the convex hull inward, and a
    # hole point outside the hull crashes it: only those strictly inside are given.
    hull = shapely.MultiPoint(coordinates).convex_hull
    inner = (
        [
            point
            for point in holes
            if shapely.contains_xy(hull, *point)
            and hull.exterior.distance(shapely.Point(point)) > 0.0
        ]
        if hull.geom_type == "Polygon"
        else []
    )
    if inner:
        data["holes"] = np.asarray(inner, dtype=np.float64)
    steiner = STEINER_PER_TRIANGLE * len(corridor)
    result = triangulate_in_frame(data, f"pq{MIN_ANGLE:g}YYAaS{steiner}Q")
    made = np.asarray(result["vertices"], dtype=np.float64)
    pieces_of = np.asarray(result["triangles"], dtype=np.int64)
    owners = np.rint(np.asarray(result["triangle_attributes"], dtype=np.float64)[:, 0])
    if len(made) < len(given) or not np.array_equal(made[: len(given)], given):
        return abstraction, []  # (Triangle keeps the points it is given, in order)
    owner = owners.astype(np.int64) - 1
    if (owner < 0).any() or not _tiles(abstraction, corridor, made, pieces_of, owner):
        return abstraction, []
    # (a triangle left whole may be thinner than the floor already)
    allowed = [min(floor, triangle_inradius(points[tri[t]])) for t in corridor]
    if any(
        triangle_inradius(corners) < allowed[k]
        for corners, k in zip(made[pieces_of], owner.tolist(), strict=True)
    ):
        return abstraction, []
    # local point ids -> mesh ids: the corridor's own, then the new points appended
    ids = np.concatenate(
        [np.asarray(old_ids, dtype=np.int64), len(points) + np.arange(len(made) - len(old_ids))]
    )
    vertices = np.vstack([points, made[len(old_ids) :]])
    triangles = tri.copy()
    letter_of = abstraction.letter_of.copy()
    component = abstraction.component.copy()
    appended: list[list[int]] = []
    parents: list[int] = []
    taken = np.zeros(len(corridor), dtype=bool)
    for piece, k in enumerate(owner.tolist()):
        t = corridor[k]
        row = ids[pieces_of[piece]].tolist()
        if not taken[k]:
            taken[k] = True
            triangles[t] = row
        else:
            appended.append(row)
            parents.append(t)
    if appended:
        triangles = np.vstack([triangles, np.asarray(appended, dtype=np.int64)])
        letter_of = np.concatenate([letter_of, letter_of[parents]])
        component = np.concatenate([component, component[parents]])
    refined = with_splits(
        abstraction,
        vertices,
        (triangles, _neighbors(triangles), letter_of, component),
        start_point,
        counter="corridor_refinements",
        count=int(on_route.sum()),
    )
    return refined, parents


def _outside(corners: FloatArray, side: int) -> FloatArray:
    """A point just across the edge of a triangle opposite corner ``side``."""
    a, b, c = corners[(side + 1) % 3], corners[(side + 2) % 3], corners[side]
    middle = (a + b) / 2.0
    return middle + 1e-3 * (middle - c)  # type: ignore[no-any-return]


def _tiles(
    abstraction: Abstraction,
    corridor: list[int],
    made: FloatArray,
    pieces: np.ndarray,
    owner: np.ndarray,
) -> bool:
    """Whether the pieces tile their triangles: counter-clockwise, and the areas of each
    triangle's pieces sum to its own."""
    areas = _signed_areas(made[pieces])
    if (areas <= 0.0).any():
        return False
    sums = np.zeros(len(corridor))
    np.add.at(sums, owner, areas)
    expected = _signed_areas(abstraction.vertices[abstraction.triangles[corridor]])
    return bool(np.allclose(sums, expected, rtol=1e-9, atol=0.0))


def _signed_areas(corners: FloatArray) -> FloatArray:
    """Each triangle's area, (k, 3, 2) corners: positive when counter-clockwise."""
    u, w = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    areas: FloatArray = (u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]) / 2.0
    return areas


def _neighbors(triangles: np.ndarray) -> np.ndarray:
    """The triangle across each edge (opposite each corner), -1 where none."""
    count = len(triangles)
    low = np.minimum(triangles[:, [1, 2, 0]], triangles[:, [2, 0, 1]]).ravel()
    high = np.maximum(triangles[:, [1, 2, 0]], triangles[:, [2, 0, 1]]).ravel()
    order = np.lexsort((high, low))
    same = (low[order][1:] == low[order][:-1]) & (high[order][1:] == high[order][:-1])
    first, second = order[:-1][same], order[1:][same]
    result = np.full(3 * count, -1, dtype=np.int64)
    result[first] = second // 3
    result[second] = first // 3
    return result.reshape(count, 3)
