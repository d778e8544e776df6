"""Point location on the triangulation: which triangle holds a point, and which triangles a
straight move crosses (so that no triangle the robot passes through goes unread, however
coarse the samples).

Barycentric coordinates are λ_i(x) = (c_i − n_i·x) / h_i with the outward unit normal n_i of
facet i (opposite vertex i), its offset c_i and the height h_i over it, for every triangle at
once.  A point lies in a triangle when every λ_i >= −TOLERANCE: the tolerance (relative to the
triangle, since λ is) lets a point on a shared edge belong to both, and the walk then keeps the
triangle it is in, so an edge never flickers between two triangles.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray

#: Barycentric slack: a point this far (relative to the triangle) outside still counts as in.
TOLERANCE = 1e-9
#: A walk longer than this many triangles is abandoned for a global search (a degenerate
#: walk along an edge or through a vertex could otherwise cycle).
MAX_WALK = 100_000


@dataclass(frozen=True, slots=True)
class Locator:
    """Every triangle's facet normals, offsets and heights, for barycentric coordinates."""

    abstraction: Abstraction = field(repr=False)
    normals: FloatArray = field(repr=False)  # (m, 3, 2)
    offsets: FloatArray = field(repr=False)  # (m, 3)
    heights: FloatArray = field(repr=False)  # (m, 3)

    @classmethod
    def of(cls, abstraction: Abstraction) -> Locator:
        """The locator of ``abstraction`` (triangles are counter-clockwise)."""
        corners = abstraction.vertices[abstraction.triangles]  # (m, 3, 2)
        a = np.roll(corners, -1, axis=1)  # vertex i+1: facet i runs from it ...
        b = np.roll(corners, -2, axis=1)  # ... to vertex i+2
        edge = b - a
        normals = np.stack([edge[..., 1], -edge[..., 0]], axis=-1)
        normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
        offsets = np.einsum("mij,mij->mi", normals, a)
        heights = offsets - np.einsum("mij,mij->mi", normals, corners)
        return cls(abstraction, normals, offsets, heights)

    def barycentric(self, triangle: int, point: FloatArray) -> FloatArray:
        """λ of ``point`` in ``triangle`` (three numbers summing to one)."""
        offsets, normals = self.offsets[triangle], self.normals[triangle]
        lam: FloatArray = (offsets - normals @ point) / self.heights[triangle]
        return lam

    def contains(self, triangle: int, point: FloatArray) -> bool:
        """True when ``point`` lies in the closed ``triangle`` (up to :data:`TOLERANCE`)."""
        return bool(self.barycentric(triangle, point).min() >= -TOLERANCE)

    def locate(self, point: FloatArray) -> int | None:
        """The triangle holding ``point`` (the one it is deepest in), None outside them all."""
        lam = (self.offsets - self.normals @ point) / self.heights
        depth = lam.min(axis=1)
        best = int(np.argmax(depth))
        return best if depth[best] >= -TOLERANCE else None

    def walk(self, triangle: int, start: FloatArray, end: FloatArray) -> list[int] | None:
        """The triangles the segment ``start -> end`` enters after ``triangle``, in order.

        ``start`` lies in ``triangle``.  Empty when ``end`` is still in ``triangle``; None when
        the segment leaves the triangulation (into a hole or out of the workspace) or the walk
        degenerates: the caller then locates ``end`` globally.
        """
        neighbors: IntArray = self.abstraction.neighbors
        entered: list[int] = []
        current, reached = triangle, 0.0
        for _ in range(MAX_WALK):
            at_end = self.barycentric(current, end)
            if at_end.min() >= -TOLERANCE:
                return entered
            at_start = self.barycentric(current, start)
            # The segment leaves ``current`` through the facet whose λ reaches 0 first after
            # the point where it came in.
            exit_facet, exit_at = -1, np.inf
            for facet in range(3):
                if at_end[facet] >= 0.0 or at_start[facet] <= at_end[facet]:
                    continue
                crossing = at_start[facet] / (at_start[facet] - at_end[facet])
                if crossing >= reached - 1e-12 and crossing < exit_at:
                    exit_facet, exit_at = facet, crossing
            if exit_facet < 0:
                return None
            following = int(neighbors[current, exit_facet])
            if following < 0:
                return None
            current, reached = following, float(exit_at)
            entered.append(current)
        return None
