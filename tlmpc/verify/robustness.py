"""Spatial robustness (Fainekos–Pappas) of a sampled trajectory.

A proposition's robustness at a sample is its signed distance to the region's boundary
(positive inside); negation flips the sign, and/or take min/max, and until is the max-min
recursion rho(i) = max(rho_b(i), min(rho_a(i), rho(i+1))) with the last sample repeated (a
finite trace) or the loop wrapped (a lasso).  F and G are reverse running max/min.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import numpy.typing as npt
import shapely

from tlmpc.ltl.ast import (
    And,
    Const,
    Equiv,
    Eventually,
    Formula,
    Globally,
    Implies,
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
)

FloatArray = npt.NDArray[np.float64]


def signed_distance(
    polygon: FloatArray, points: FloatArray, geoms: npt.NDArray[np.object_] | None = None
) -> FloatArray:
    """+distance to the boundary inside (closed) the polygon, -distance to it outside.

    Regions have no holes, so the distance to the polygon from outside equals the distance to
    its exterior ring: one distance computation serves both signs.
    """
    shape = shapely.Polygon(polygon)
    if geoms is None:
        geoms = shapely.points(points)
    distance = np.asarray(shapely.distance(shape.exterior, geoms), dtype=np.float64)
    inside = shapely.contains_xy(shape, points[:, 0], points[:, 1])
    # Boundary points are inside a closed region: distance 0, sign irrelevant.
    result: FloatArray = np.where(inside, distance, -distance)
    return result


class _Robustness:
    def __init__(
        self, points: FloatArray, loop_start: int | None, regions: Mapping[str, FloatArray]
    ) -> None:
        self.points = points
        self.geoms = shapely.points(points)
        self.size = len(points)
        self.loop = loop_start
        self.regions = regions
        self.cache: dict[Formula, FloatArray] = {}

    def __call__(self, f: Formula) -> FloatArray:
        if f not in self.cache:
            self.cache[f] = self._eval(f)
        return self.cache[f]

    def _eventually(self, b: FloatArray) -> FloatArray:
        result = np.maximum.accumulate(b[::-1])[::-1]
        if self.loop is not None:
            result[self.loop :] = np.maximum(result[self.loop :], b[self.loop :].max())
        return np.asarray(result, dtype=np.float64)

    def _until(self, a: FloatArray, b: FloatArray) -> FloatArray:
        values = np.full(self.size, -np.inf)
        a_list, b_list = a.tolist(), b.tolist()
        out = values.tolist()
        last = self.size - 1
        passes = 2 if self.loop is not None else 1
        for _ in range(passes):
            for i in range(last, -1, -1):
                if i == last:
                    following = out[self.loop] if self.loop is not None else b_list[i]
                else:
                    following = out[i + 1]
                out[i] = max(b_list[i], min(a_list[i], following))
        return np.asarray(out)

    def _eval(self, f: Formula) -> FloatArray:
        if isinstance(f, Const):
            return np.full(self.size, np.inf if f.value else -np.inf)
        if isinstance(f, Prop):
            return signed_distance(np.asarray(self.regions[f.name]), self.points, self.geoms)
        if isinstance(f, Not):
            return -self(f.arg)
        if isinstance(f, And):
            return np.minimum.reduce([self(a) for a in f.args])  # type: ignore[no-any-return]
        if isinstance(f, Or):
            return np.maximum.reduce([self(a) for a in f.args])  # type: ignore[no-any-return]
        if isinstance(f, Implies):
            return np.maximum(-self(f.left), self(f.right))
        if isinstance(f, Equiv):
            a, b = self(f.left), self(f.right)
            return np.minimum(np.maximum(-a, b), np.maximum(a, -b))
        if isinstance(f, Eventually):
            return self._eventually(self(f.arg))
        if isinstance(f, Globally):
            return -self._eventually(-self(f.arg))
        if isinstance(f, Until):
            return self._until(self(f.left), self(f.right))
        if isinstance(f, Release):
            return -self._until(-self(f.left), -self(f.right))
        if isinstance(f, WeakUntil):
            left = self(f.left)
            return np.maximum(self._until(left, self(f.right)), -self._eventually(-left))
        if isinstance(f, StrongRelease):
            right = self(f.right)
            return self._until(right, np.minimum(self(f.left), right))
        raise TypeError(f"not an LTL node: {f!r}")


def robustness(
    formula: Formula,
    times: FloatArray,
    points: FloatArray,
    loop_start: int | None,
    regions: Mapping[str, FloatArray],
) -> float:
    """Robustness of ``formula`` at the first sample."""
    del times
    return float(_Robustness(points, loop_start, regions)(formula)[0])
