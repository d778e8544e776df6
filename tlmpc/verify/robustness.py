"""Spatial robustness (Fainekos–Pappas) on the pieces of the trajectory, and the certificate.

Robustness of a proposition at a position is the signed distance to its region's boundary
(positive inside).  Two evaluations use it, both through :mod:`tlmpc.verify.semantics`:

* **The reported robustness** is evaluated on the same pieces as the verdict (every sample and
  every boundary crossing of the piecewise-linear trajectory, and the stretches between them,
  each stretch represented by its midpoint), with each distance's sign forced to agree with the
  piece's label (a boundary point, at distance 0, may carry either label).  Since the recursion
  is the verdict's own, by induction over the formula robustness > 0 implies the verdict holds
  and < 0 that it fails: the two never disagree in sign.
* **The certificate** is evaluated on the samples as the robot may really have moved between
  them: at speed at most ``max_speed``, the robot is within ``r_i = max_speed × (half the longer
  of the gaps next to sample i)`` of sample i throughout the time nearer to it than to its
  neighbours, so each proposition's distance there lies in ``[d_i - r_i, d_i + r_i]``.
  Interval evaluation of the formula then bounds the robustness of every such motion: a lower
  bound > 0 proves the task holds, an upper bound < 0 that it fails.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np
import numpy.typing as npt
import shapely

from tlmpc.verify.evaluate import Value

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


#: Polygons with at most this many edges get their distances from numpy directly (shapely's
#: per-point distance dominates the run time on long logs against small regions).
DIRECT_EDGES = 32


#: Points per block of :func:`_ring_distance`: a block's buffers stay in the processor's cache
#: through every edge (a multiple of the BLAS kernels' row blocks, so each row's product is
#: computed as on the whole array).
RING_BLOCK = 4096


def _ring_distance(polygon: FloatArray, points: FloatArray) -> FloatArray:
    """Distance from each point to the polygon's boundary, edge by edge.

    Per edge: the offsets from its start, their projection onto it clamped to the edge, and
    the length of what is left.  The buffers are allocated once and the (n, 2) arithmetic
    runs one coordinate at a time: numpy's loops over rows of two (``points - start``,
    ``along[:, None] * edge``) and a fresh array per step cost more than the arithmetic on
    a trace of 10^5 points.  The points go :data:`RING_BLOCK` at a time through all the
    edges, so that a block's buffers are read again from the cache rather than from memory.
    The values are those of the row-wise form (the same operations on the same numbers; the
    projection is the same matrix-vector product on the same (n, 2) layout).
    """
    count = len(points)
    best = np.full(count, np.inf)
    width = min(count, RING_BLOCK)
    offset_buffer = np.empty((width, 2))  # ``points - start``, row-wise, for the projection
    gap_buffer = np.empty((2, width))
    along_buffer = np.empty(width)
    ends = np.roll(polygon, -1, axis=0)
    edges = [(start, end - start) for start, end in zip(polygon, ends, strict=True)]
    lengths = [float(edge @ edge) for _, edge in edges]
    for first in range(0, count, RING_BLOCK):
        size = min(RING_BLOCK, count - first)
        xs, ys = points[first : first + size, 0], points[first : first + size, 1]
        offset, gap = offset_buffer[:size], gap_buffer[:, :size]
        along, nearest = along_buffer[:size], best[first : first + size]
        for (start, edge), length in zip(edges, lengths, strict=True):
            np.subtract(xs, start[0], out=offset[:, 0])
            np.subtract(ys, start[1], out=offset[:, 1])
            if length > 0:
                np.matmul(offset, edge, out=along)
                np.divide(along, length, out=along)
                np.clip(along, 0.0, 1.0, out=along)
            else:
                along.fill(0.0)
            for axis in (0, 1):
                np.multiply(along, edge[axis], out=gap[axis])
                np.subtract(offset[:, axis], gap[axis], out=gap[axis])
            np.hypot(gap[0], gap[1], out=gap[0])
            np.minimum(nearest, gap[0], out=nearest)
    return best


#: Polygons with more edges than this get their distances through an index over pieces of
#: their ring (:func:`_indexed_ring_distance`): GEOS measures a point against every edge, and
#: a finely drawn region (thousands of vertices) against a densely resampled trace (10^5
#: samples) took minutes.  Below it the index costs more than it saves (measured: even at
#: about 600 edges, 1.6 x faster at 1,000, 4.5 x at 6,000).
INDEXED_EDGES = 1000

#: Consecutive edges per piece of the ring in the index: fewer pieces to search, each a short
#: run of edges measured at C speed.
EDGES_PER_PIECE = 16


def _indexed_ring_distance(ring: shapely.LinearRing, geoms: npt.NDArray[np.object_]) -> FloatArray:
    """GEOS's distance from each point to ``ring``, the same numbers, found through an
    R-tree over runs of :data:`EDGES_PER_PIECE` edges: the distance to a line is the least
    over its edges, and the tree's nearest piece holds the nearest edge."""
    coords = shapely.get_coordinates(ring)
    edges = len(coords) - 1
    firsts = np.arange(0, edges, EDGES_PER_PIECE)
    lasts = np.minimum(firsts + EDGES_PER_PIECE, edges)
    sizes = lasts - firsts + 1  # a piece's vertices, its last shared with the next piece
    take = np.repeat(firsts - np.cumsum(sizes) + sizes, sizes) + np.arange(int(sizes.sum()))
    pieces = shapely.linestrings(coords[take], indices=np.repeat(np.arange(len(sizes)), sizes))
    (which, _), distance = shapely.STRtree(pieces).query_nearest(
        geoms, return_distance=True, all_matches=False
    )
    result: FloatArray = np.empty(len(geoms), dtype=np.float64)
    result[which] = distance
    return result


def _contains(shape: shapely.Polygon, corners: FloatArray, points: FloatArray) -> BoolArray:
    """``shapely.contains_xy`` of each point: asked only of the points in the polygon's
    (closed) bounding box, since no point outside it lies in the polygon's interior (a region
    is small against a trace that crosses the whole map)."""
    xs, ys = points[:, 0], points[:, 1]
    (left, bottom), (right, top) = corners.min(axis=0), corners.max(axis=0)
    near = np.flatnonzero((xs >= left) & (xs <= right) & (ys >= bottom) & (ys <= top))
    inside = np.zeros(len(points), dtype=bool)
    inside[near] = shapely.contains_xy(shape, xs[near], ys[near])
    return inside


def signed_distance(
    polygon: FloatArray, points: FloatArray, geoms: npt.NDArray[np.object_] | None = None
) -> FloatArray:
    """+distance to the boundary inside (closed) the polygon, -distance to it outside.

    Regions have no holes, so the distance to the polygon from outside equals the distance to
    its exterior ring: one distance computation serves both signs.
    """
    shape = shapely.Polygon(polygon)
    corners = np.asarray(polygon, dtype=np.float64)
    if len(polygon) <= DIRECT_EDGES:
        distance = _ring_distance(corners, points)
    else:
        if geoms is None:
            geoms = shapely.points(points)
        if len(polygon) > INDEXED_EDGES:
            distance = _indexed_ring_distance(shape.exterior, geoms)
        else:
            distance = np.asarray(shapely.distance(shape.exterior, geoms), dtype=np.float64)
    inside = _contains(shape, corners, points)
    result: FloatArray = np.where(inside, distance, -distance)
    return result


def piece_atoms(
    regions: Mapping[str, FloatArray],
    positions: FloatArray,
    labels: BoolArray,
    unknown: BoolArray | None,
) -> Callable[[str], Value]:
    """Signed distances at the pieces' positions, signs forced to the pieces' labels."""
    names = list(regions)
    geoms = None
    cache: dict[str, Value] = {}

    def atom(name: str) -> Value:
        if name not in cache:
            index = names.index(name)
            distance = signed_distance(np.asarray(regions[name]), positions, geoms)
            # Rounding can put a point a hair outside a region its label says it is in.
            value = np.where(labels[:, index], np.maximum(distance, 0.0), np.minimum(distance, 0.0))
            if unknown is not None:
                value = np.where(unknown[:, index], 0.0, value)
            cache[name] = (value, value)
        return cache[name]

    return atom


#: Relative slack on the speed check, beyond the rounding of the samples' own numbers.
SPEED_SLACK = 1e-9


def speed_excess(times: FloatArray, points: FloatArray, max_speed: float) -> FloatArray:
    """Per gap between consecutive samples, how much longer its chord is than ``max_speed``
    allows over its time, beyond :data:`SPEED_SLACK` and the floating-point rounding of its
    ends (0 where it is not): the speed check of the certificate, of a streamed log and of
    the compile's self-check.  The rounding matters across slivers: a chord 1e-8 long takes
    1e-8 s, and the rounding of t ~ 10 and x ~ 5 alone is 1e-7 of its speed."""
    gaps = np.diff(times)
    chords = np.hypot(*np.diff(points, axis=0).T)
    ends = np.abs(points[:-1]) + np.abs(points[1:])
    spans = np.abs(times[:-1]) + np.abs(times[1:])
    rounding = 8.0 * np.finfo(np.float64).eps * (ends[:, 0] + ends[:, 1] + max_speed * spans)
    allowed = max_speed * gaps * (1.0 + SPEED_SLACK) + rounding
    excess: FloatArray = np.maximum(chords - allowed, 0.0)
    return excess


def tube_radii(times: FloatArray, max_speed: float) -> FloatArray:
    """How far the robot may be from each sample while that sample is the nearest in time."""
    gaps = np.diff(times)
    before = np.concatenate([[0.0], gaps])
    after = np.concatenate([gaps, [0.0]])
    radii: FloatArray = max_speed * np.maximum(before, after) / 2.0
    return radii


def tube_atoms(
    regions: Mapping[str, FloatArray], points: FloatArray, radii: FloatArray
) -> Callable[[str], Value]:
    """Signed distance ± the sample's radius: bounds on the distance around each sample."""
    geoms = None
    cache: dict[str, Value] = {}

    def atom(name: str) -> Value:
        if name not in cache:
            distance = signed_distance(np.asarray(regions[name]), points, geoms)
            cache[name] = (distance - radii, distance + radii)
        return cache[name]

    return atom
