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


def _ring_distance(polygon: FloatArray, points: FloatArray) -> FloatArray:
    """Distance from each point to the polygon's boundary, edge by edge."""
    best = np.full(len(points), np.inf)
    for start, end in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        edge = end - start
        length = float(edge @ edge)
        offset = points - start
        along = np.clip(offset @ edge / length, 0.0, 1.0) if length > 0 else np.zeros(len(points))
        gap = offset - along[:, None] * edge
        np.minimum(best, np.hypot(gap[:, 0], gap[:, 1]), out=best)
    return best


def signed_distance(
    polygon: FloatArray, points: FloatArray, geoms: npt.NDArray[np.object_] | None = None
) -> FloatArray:
    """+distance to the boundary inside (closed) the polygon, -distance to it outside.

    Regions have no holes, so the distance to the polygon from outside equals the distance to
    its exterior ring: one distance computation serves both signs.
    """
    shape = shapely.Polygon(polygon)
    if len(polygon) <= DIRECT_EDGES:
        distance = _ring_distance(np.asarray(polygon, dtype=np.float64), points)
    else:
        if geoms is None:
            geoms = shapely.points(points)
        distance = np.asarray(shapely.distance(shape.exterior, geoms), dtype=np.float64)
    inside = shapely.contains_xy(shape, points[:, 0], points[:, 1])
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
