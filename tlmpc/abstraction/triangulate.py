"""Observation-preserving constrained Delaunay triangulation of a mission's workspace.

The free space (boundary minus holes) and every region boundary clipped to it are noded with
shapely (crossing boundaries of overlapping regions meet at a vertex), then handed to
Shewchuk's Triangle as a planar straight-line graph.  Because every region boundary is a
chain of constraint segments, each triangle lies wholly inside or wholly outside each region.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from itertools import chain
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt
import shapely
import triangle
from shapely.geometry import Polygon as ShapelyPolygon

from tlmpc.base.errors import InvalidInputError, error
from tlmpc.mission.model import Mission
from tlmpc.mission.resolution import grid_size

if TYPE_CHECKING:
    from tlmpc.abstraction.layout import PlanningLayout
    from tlmpc.abstraction.lines import Lines

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: Steiner point budget of quality refinement: at least MIN_STEINER, else this many per input
#: vertex (a cap, far above what well-shaped inputs need, so refinement always terminates).
MIN_STEINER = 20_000
STEINER_PER_VERTEX = 50
#: Segments at most this many grid steps long are contracted to a point (two neighbouring
#: pixels are at most the square root of two apart).
CLOSE_PIXELS = 2.0
#: A hole seed lies at least this many grid steps inside its piece of obstacle space:
#: snapping moves the sides around it by at most a step's half diagonal each time.
SEED_DEPTH = 2.0


def exact_shift(values: FloatArray) -> float:
    """An offset ``o`` whose subtraction is exact for every one of ``values`` (Sterbenz: ``x - o``
    is exact when ``o / 2 <= x <= 2 o``), as near them as that allows: their least magnitude
    when they all lie on one side of zero within a factor of two of it, else 0."""
    if not len(values):
        return 0.0
    low, high = float(values.min()), float(values.max())
    if low > 0.0 and high <= 2.0 * low:
        return low
    if high < 0.0 and low >= 2.0 * high:
        return high
    return 0.0


def triangulate_in_frame(data: dict[str, Any], options: str) -> dict[str, Any]:
    """``triangle.triangulate(data, options)`` with the coordinates moved next to the origin.

    Triangle's refinement computes new points (circumcentres, segment midpoints) in absolute
    coordinates: far from the origin (a map of a centimetre at a million metres) they lose
    the digits that tell the features apart, and Triangle crashes the process. The vertices,
    hole seeds and region points are shifted by an offset whose subtraction is exact
    (:func:`exact_shift` per axis), so the geometry Triangle sees is the input's bit for bit;
    the output's vertices are shifted back, which gives the input vertices (Triangle keeps
    them first and in order, ``p``) bit for bit: ``(x - o) + o`` is ``x`` when ``x - o`` is
    exact."""
    given = np.asarray(data["vertices"], dtype=np.float64)
    shift = np.array([exact_shift(given[:, 0]), exact_shift(given[:, 1])])
    if not shift.any():
        return dict(triangle.triangulate(data, options))
    local = dict(data)
    local["vertices"] = given - shift
    for key in ("holes", "regions"):
        if key in data:
            moved = np.array(data[key], dtype=np.float64)
            moved[:, :2] -= shift
            local[key] = moved
    result = dict(triangle.triangulate(local, options))
    result["vertices"] = np.asarray(result["vertices"], dtype=np.float64) + shift
    return result


def _snapped(points: Sequence[tuple[float, float]], grid: float) -> Any:
    return shapely.set_precision(ShapelyPolygon(points), grid)


def polygon_coordinates(
    polygons: Sequence[Sequence[tuple[float, float]]],
) -> tuple[FloatArray, IntArray]:
    """All vertices of ``polygons`` as one (n, 2) array, and the polygon each belongs to.

    One conversion of the chained points (an array per polygon costs several times more on
    maps of a hundred thousand rooms).
    """
    lengths = list(map(len, polygons))
    coords = np.array(list(chain.from_iterable(polygons)), dtype=np.float64).reshape(-1, 2)
    owner = np.repeat(np.arange(len(polygons), dtype=np.int64), lengths)
    return coords, owner


def _snapped_many(polygons: Sequence[Sequence[tuple[float, float]]], grid: float) -> list[Any]:
    """:func:`_snapped` for many polygons at once (vectorised: maps with thousands of rooms)."""
    if not polygons:
        return []
    coords, owner = polygon_coordinates(polygons)
    rings = shapely.linearrings(coords, indices=owner)
    shapes = shapely.polygons(rings)
    # Snap-rounding costs a GEOS overlay per polygon; polygons already on the grid (the usual
    # case: coordinates written in decimals) are left as they are.
    scaled = coords / grid
    off_grid = np.abs(scaled - np.round(scaled)).max(axis=1) > 1e-6
    needs = np.zeros(len(polygons), dtype=bool)
    np.logical_or.at(needs, owner, off_grid)
    if needs.any():
        shapes[needs] = shapely.set_precision(shapes[needs], grid)
    return list(shapes)


def _piece_free(boundary_points: Any, hole_points: Any, grid: float) -> Any:
    boundary = _snapped(boundary_points, grid)
    if hole_points:
        holes = shapely.union_all([_snapped(h, grid) for h in hole_points])
        boundary = shapely.set_precision(boundary.difference(holes), grid)
    return boundary


def free_space(mission: Mission, grid: float) -> Any:
    """The workspace boundary minus the holes, snapped to ``grid``; with further workspace
    components, the union of every piece's boundary minus its own holes."""
    boundary = _piece_free(mission.workspace.boundary, mission.workspace.holes, grid)
    if mission.workspace.components:
        pieces = [boundary] + [
            _piece_free(c.boundary, c.holes, grid) for c in mission.workspace.components
        ]
        boundary = shapely.union_all(pieces, grid_size=grid)
    if boundary.is_empty:
        raise InvalidInputError(
            error(
                "A001",
                "the holes cover the whole workspace: there is no free space",
                hint="shrink the holes",
                file=mission.source,
            )
        )
    return boundary


def _snapped_free(free: Any, grid: float, mission: Mission) -> Any:
    """A layout's free space on the grid (snapping, and noding with the regions' rings, move
    a vertex by at most a grid step's half diagonal each, less than the two grid steps the
    layout's erosion adds)."""
    snapped = shapely.set_precision(free, grid)
    if snapped.is_empty:
        raise InvalidInputError(
            error(
                "R001",
                "the robot's body fits nowhere: the free space vanishes once obstacles are "
                "inflated by the robot's radius",
                hint="give a smaller robot.radius / footprint, or widen the workspace",
                file=mission.source,
            )
        )
    return snapped


def _polygons(geometry: Any) -> list[ShapelyPolygon]:
    if isinstance(geometry, ShapelyPolygon):
        return [geometry] if not geometry.is_empty else []
    if hasattr(geometry, "geoms"):
        result: list[ShapelyPolygon] = []
        for part in geometry.geoms:
            result.extend(_polygons(part))
        return result
    return []


def _hole_seed(piece: ShapelyPolygon, grid: float) -> tuple[Any, float]:
    """A point of ``piece`` for Triangle to carve it out from, and its distance to the
    piece's boundary.

    Triangle eats every triangle it reaches from a seed without crossing a segment, so a
    seed must lie in ``piece`` after snapping moved its sides.  The representative point can
    lie in a sliver of the piece (a hair from its side, so in the free space beside it once
    snapped: the whole piece of free space is then eaten); the pole of inaccessibility is
    taken instead when the representative point is not :data:`SEED_DEPTH` grid steps deep.
    """
    point = piece.representative_point()
    depth = float(piece.boundary.distance(point))
    if depth > SEED_DEPTH * grid:
        return point, depth
    from shapely.ops import polylabel

    minx, miny, maxx, maxy = piece.bounds
    deepest = polylabel(piece, tolerance=max(1e-3 * max(maxx - minx, maxy - miny), grid))
    deepest_depth = float(piece.boundary.distance(deepest))
    return (deepest, deepest_depth) if deepest_depth > depth else (point, depth)


def _rings(polygon: ShapelyPolygon) -> list[Any]:
    return [polygon.exterior, *polygon.interiors]


def _rings_of_all(shapes: Sequence[Any]) -> list[Any]:
    """Every ring of every polygon part of ``shapes``, in order (exterior, then holes).

    Plain polygons without holes (rooms) take their exterior ring in one vectorised call;
    anything else goes through :func:`_polygons` and :func:`_rings`.
    """
    if not shapes:
        return []
    array = np.asarray(shapes, dtype=object)
    plain = (
        (shapely.get_type_id(array) == shapely.GeometryType.POLYGON)
        & ~shapely.is_empty(array)
        & (shapely.get_num_interior_rings(array) == 0)
    )
    if bool(plain.all()):
        return list(shapely.get_exterior_ring(array))
    rings: list[Any] = []
    for shape, simple in zip(shapes, plain.tolist(), strict=True):
        if simple:
            rings.append(shape.exterior)
        else:
            rings.extend(ring for part in _polygons(shape) for ring in _rings(part))
    return rings


def _unique_rows(rows: IntArray) -> tuple[IntArray, IntArray]:
    """``np.unique(rows, axis=0, return_index=True, return_inverse=True)`` for two columns
    of integers, without the answer itself: each distinct row's first index (rows sorted
    lexicographically) and each row's rank among the distinct rows.

    Rows are packed into one integer (column 0 times the span of column 1, plus column 1,
    both shifted to start at 0) when that fits, which orders them exactly as the
    lexicographic row order and is several times faster than sorting rows as records.
    """
    if len(rows) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    low = rows.min(axis=0)
    span = rows.max(axis=0) - low + 1
    if int(span[0]) * int(span[1]) < 2**62:
        packed = (rows[:, 0] - low[0]) * span[1] + (rows[:, 1] - low[1])
        # np.unique(packed, return_index=True, return_inverse=True), with an unstable sort:
        # each group's first index is its smallest one (half the time on a million rows).
        order = np.argsort(packed)
        ordered = packed[order]
        starts = np.empty(len(ordered), dtype=bool)
        starts[0] = True
        np.not_equal(ordered[1:], ordered[:-1], out=starts[1:])
        group = np.cumsum(starts) - 1
        inverse = np.empty(len(ordered), dtype=np.int64)
        inverse[order] = group
        first = np.full(int(group[-1]) + 1, len(ordered), dtype=np.int64)
        np.minimum.at(first, group, order)
    else:
        _, first, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    return np.asarray(first, dtype=np.int64), np.asarray(inverse, dtype=np.int64).reshape(-1)


def _chains_of(lines: Sequence[Any]) -> tuple[FloatArray, IntArray]:
    """The points of the given linework, line after line, and the straight segments as the
    index of each one's first point (the second is the next point, of the same line)."""
    points, owner = shapely.get_coordinates(lines, return_index=True)
    if len(points) < 2:
        return np.zeros((0, 2)), np.zeros(0, dtype=np.int64)
    starts: IntArray = np.flatnonzero(owner[1:] == owner[:-1])
    return points, starts


def _needs_noding(rings: list[Any], grid: float) -> bool:
    """True when some ring crosses, touches or comes within a grid step of another (then the
    linework must be noded: a corner snapped a hair beside another ring's slanted side is on
    it for the snap-rounding noder, but would reach Triangle as a vertex a rounding error
    from a segment, which it cannot mesh)."""
    if len(rings) <= 1:
        return False
    tree = shapely.STRtree(rings)
    pairs = tree.query(rings, predicate="dwithin", distance=grid)
    return bool(np.any(pairs[0] != pairs[1]))


def _inside(free: Any, rings: list[Any]) -> list[Any]:
    """The rings (none meeting ``free``'s boundary) that lie in ``free``."""
    if not rings:
        return []
    first = shapely.get_coordinates(shapely.get_point(np.asarray(rings, dtype=object), 0))
    keep = shapely.intersects_xy(free, first[:, 0], first[:, 1])
    return [ring for ring, k in zip(rings, keep.tolist(), strict=True) if k]


def _merge_close(
    vertices: FloatArray,
    edges: IntArray,
    tolerance: float,
    keys: IntArray,
    written: Callable[[], IntArray],
) -> tuple[FloatArray, IntArray]:
    """The graph with every segment no longer than ``tolerance`` between two points that
    noding made (neither one's grid key is among the keys ``written`` gives of the rings'
    vertices) contracted to its end of
    lower index. Snap rounding can node one crossing at two neighbouring pixels (a region's
    side clipped at a hole's side, and that side noded where the region's side crosses it): a
    segment one pixel long that Triangle would keep as a needle triangle joining a region to
    the space beside it. Short sides the map itself has (a needle drawn as such, a body's
    configuration space) are kept as they are."""
    span = vertices[edges[:, 1]] - vertices[edges[:, 0]]
    short = np.hypot(span[:, 0], span[:, 1]) <= tolerance
    if not short.any():
        return vertices, edges
    drawn = {tuple(key) for key in written().tolist()}
    made = np.array([tuple(key) not in drawn for key in keys.tolist()])
    short &= made[edges[:, 0]] & made[edges[:, 1]]
    if not short.any():
        return vertices, edges
    owner: dict[int, int] = {}

    def find(vertex: int) -> int:
        while owner.get(vertex, vertex) != vertex:
            vertex = owner[vertex]
        return vertex

    for a, b in edges[short].tolist():
        x, y = find(a), find(b)
        if x != y:
            owner[max(x, y)] = min(x, y)
    root = np.arange(len(vertices))
    for vertex in owner:
        root[vertex] = find(vertex)
    kept = root == np.arange(len(vertices))
    renumber = np.cumsum(kept) - 1
    merged = renumber[root[edges]]
    merged = np.sort(merged[merged[:, 0] != merged[:, 1]], axis=1)
    return vertices[kept], merged[_unique_rows(merged)[0]]


def pslg(
    mission: Mission, layout: PlanningLayout | None = None, *, lines: Lines | None = None
) -> tuple[FloatArray, IntArray, FloatArray, list[Any]]:
    """The planar straight-line graph and the snapped region shapes.

    Returns vertices, segments (index pairs), hole seed points, and each region's polygon
    after snapping to the grid (the shapes whose boundaries are the constraint segments).
    All geometry is snap-rounded to a grid of a billionth of the workspace's extent, so
    nearly touching or nearly collinear input becomes exactly touching or collinear.
    With ``lines``, the linework of a convex cells' mesh (:mod:`tlmpc.abstraction.lines`):
    every side extended across the free space (``"arrangement"``) or the reflex corners cut
    (``"reflex"``, ``"bisector"``; :class:`~tlmpc.abstraction.lines.OverBudget` beyond its
    work budget).
    """
    grid = grid_size(mission)
    if layout is None or layout.free is None:
        free = free_space(mission, grid)
        regions = _snapped_many([r.polygon for r in mission.regions], grid)
        if layout is not None:  # a point robot's goal cores
            regions = [
                own if shape is None else shapely.set_precision(shape, grid)
                for own, shape in zip(regions, layout.regions, strict=True)
            ]
    else:
        free = _snapped_free(layout.free, grid, mission)
        regions = [shapely.set_precision(shape, grid) for shape in layout.regions]
    parts = _polygons(free)
    free_rings = [ring for part in parts for ring in _rings(part)]
    region_rings = _rings_of_all(regions)
    if lines == "arrangement":
        from tlmpc.abstraction.lines import extended_lines

        clipped = [shapely.intersection(shapely.boundary(r), free, grid_size=grid) for r in regions]
        own = [*free_rings, *(c for c in clipped if not c.is_empty)]
        sides = [*free_rings, *_inside_rings(free, region_rings)]
        linework = shapely.union_all([*own, *extended_lines(free, sides)], grid_size=grid)
        points, starts = _chains_of(list(shapely.get_parts(linework)))
    elif lines in ("reflex", "bisector"):
        from tlmpc.abstraction.lines import OverBudget, reflex_extensions

        clipped = [shapely.intersection(shapely.boundary(r), free, grid_size=grid) for r in regions]
        noded = shapely.union_all(
            [*free_rings, *(c for c in clipped if not c.is_empty)], grid_size=grid
        )
        cuts = reflex_extensions(noded, free, bisectors=lines == "bisector")
        if cuts.segments is None:
            raise OverBudget(cuts.work)
        linework = shapely.union_all([noded, *cuts.segments], grid_size=grid)
        points, starts = _chains_of(list(shapely.get_parts(linework)))
    elif _needs_noding([*free_rings, *region_rings], grid):
        clipped = [shapely.intersection(shapely.boundary(r), free, grid_size=grid) for r in regions]
        linework = shapely.union_all(
            [*free_rings, *(c for c in clipped if not c.is_empty)], grid_size=grid
        )
        points, starts = _chains_of(list(shapely.get_parts(linework)))
    else:
        # No region ring meets the free space's boundary, so each ring lies wholly inside the
        # free space or wholly outside it (in a hole, or beyond the boundary).  Rings outside
        # must not become segments: Triangle would keep the triangles they enclose.
        points, starts = _chains_of([*free_rings, *_inside(free, region_rings)])
    minx, miny, _, _ = free.bounds
    # Each point once per line, not once per segment end: the same vertices (a point's first
    # appearance comes in the same order either way) from a sort of half as many keys.
    keys = np.round((points - np.array([minx, miny])) / grid).astype(np.int64)
    first, inverse = _unique_rows(keys)
    vertices = points[first]
    edges = np.stack([inverse[starts], inverse[starts + 1]], axis=1)
    edges = edges[edges[:, 0] != edges[:, 1]]
    edges = np.sort(edges, axis=1)
    edges = edges[_unique_rows(edges)[0]]
    vertices, edges = _merge_close(
        vertices,
        edges,
        CLOSE_PIXELS * grid,
        keys[first],
        lambda: np.round(
            (shapely.get_coordinates([*free_rings, *region_rings]) - np.array([minx, miny])) / grid
        ).astype(np.int64),
    )
    seeds = []
    for part in parts:
        for interior in part.interiors:
            inside = ShapelyPolygon(interior).difference(free)
            if not inside.is_empty:
                # one seed per piece: a hole may hold another piece of free space, which
                # splits the rest of the hole into several pieces (a ring, or more)
                for piece in _polygons(inside):
                    point, _ = _hole_seed(piece, grid)
                    seeds.append((point.x, point.y))
    if len(parts) > 1:
        # Pieces of free space may also enclose obstacle space between them that is no hole
        # of any one piece (pieces touching at corners): seed every bounded gap as well.
        hull = shapely.convex_hull(free)
        for gap in _polygons(hull.difference(free)):
            point, depth = _hole_seed(gap, grid)
            # A gap no deeper than the snapping moves a vertex is a rounding sliver between
            # a hull edge and the pieces' sides along it, not space they enclose (that would
            # be a gap below the grid, G031): a seed there could land in a piece once snapped.
            if depth > SEED_DEPTH * grid:
                seeds.append((point.x, point.y))
    return (
        vertices.astype(np.float64),
        edges.astype(np.int64),
        np.array(seeds, dtype=np.float64),
        regions,
    )


def triangulate(
    mission: Mission, layout: PlanningLayout | None = None
) -> tuple[FloatArray, IntArray, IntArray, list[Any]]:
    """Vertices, counter-clockwise triangles and neighbours of the constrained triangulation,
    and the snapped region shapes (use these to label the triangles).

    With a ``layout``, its free space (configuration space, margin band removed) and region
    shapes (cores of goals, grown forbidden regions) replace the mission's.
    """
    points, triangles, neighbors, regions, _ = _triangulate(mission, layout)
    return points, triangles, neighbors, regions


def lines_mesh(
    mission: Mission, layout: PlanningLayout | None = None, lines: Lines = "arrangement"
) -> tuple[FloatArray, IntArray, IntArray, list[Any], list[int]]:
    """:func:`triangulate` of a convex cells' mesh (the linework of ``lines``,
    :mod:`tlmpc.abstraction.lines`; no inner points), and the face of that linework each
    triangle lies in (numbered by its lowest triangle)."""
    points, triangles, neighbors, regions, faces = _triangulate(mission, layout, lines=lines)
    assert faces is not None
    return points, triangles, neighbors, regions, faces


def _triangulate(
    mission: Mission, layout: PlanningLayout | None = None, *, lines: Lines | None = None
) -> tuple[FloatArray, IntArray, IntArray, list[Any], list[int] | None]:
    vertices, segments, seeds, regions = pslg(mission, layout, lines=lines)
    options = "pznQ"
    # (the convex cells' mesh has no inner points: its triangles join back into its faces)
    if lines is None and mission.options.min_angle is not None and mission.options.min_angle > 0:
        options += f"q{mission.options.min_angle:g}"
        # Input angles smaller than the bound can make refinement run away (Triangle's
        # guarantee needs input angles >= 60 degrees); cap the Steiner points it may add.
        options += f"S{max(MIN_STEINER, STEINER_PER_VERTEX * len(vertices))}"
    if lines is None and mission.options.max_area is not None:
        options += f"a{mission.options.max_area:.17g}"
    data: dict[str, Any] = {"vertices": vertices, "segments": segments}
    if len(seeds):
        data["holes"] = seeds
    result = triangulate_in_frame(data, options)
    points = np.asarray(result["vertices"], dtype=np.float64)
    triangles = np.asarray(result["triangles"], dtype=np.int64)
    neighbors = np.asarray(result["neighbors"], dtype=np.int64)
    faces = _faces(triangles, neighbors, result.get("segments")) if lines is not None else None
    return points, triangles, neighbors, regions, faces


def _faces(triangles: IntArray, neighbors: IntArray, segments: Any) -> list[int]:
    """Triangles joined across every edge that is no constraint segment (lowest index)."""
    constrained = set()
    if segments is not None:
        for a, b in np.asarray(segments, dtype=np.int64).tolist():
            constrained.add((min(a, b), max(a, b)))
    rows = triangles.tolist()
    owner = list(range(len(rows)))

    def find(t: int) -> int:
        while owner[t] != t:
            owner[t] = owner[owner[t]]
            t = owner[t]
        return t

    for t, row in enumerate(neighbors.tolist()):
        for edge, there in enumerate(row):
            if there < 0:
                continue
            a, b = rows[t][(edge + 1) % 3], rows[t][(edge + 2) % 3]
            if (min(a, b), max(a, b)) in constrained:
                continue
            x, y = find(t), find(there)
            if x != y:
                owner[max(x, y)] = min(x, y)
    return [find(t) for t in range(len(rows))]


def lines_fit(mission: Mission, layout: PlanningLayout | None = None) -> bool:
    """Whether the convex cells' mesh of ``mission`` stays within its size budget
    (:data:`tlmpc.abstraction.lines.MAX_SIDES` sides to extend)."""
    from tlmpc.abstraction.lines import MAX_SIDES, side_count

    grid = grid_size(mission)
    if layout is None or layout.free is None:
        free = free_space(mission, grid)
        regions = [shapely.Polygon(r.polygon) for r in mission.regions]
    else:
        free = layout.free
        regions = [shape for shape in layout.regions if shape is not None]
    rings = [ring for part in _polygons(free) for ring in _rings(part)]
    return side_count([*rings, *_rings_of_all(regions)]) <= MAX_SIDES


def _inside_rings(free: Any, rings: list[Any]) -> list[Any]:
    """The parts of ``rings`` inside ``free`` (clipped)."""
    found = []
    for ring in rings:
        part = shapely.intersection(ring, free)
        for piece in shapely.get_parts(part):
            if piece.geom_type == "LineString" and not piece.is_empty:
                found.append(piece)
    return found
