"""The finite transition system D of the paper (stage 3 output).

States are triangles of an observation-preserving constrained Delaunay triangulation;
transitions are shared edges (self-loops, i.e. stuttering, are implicit).  Bulk data are
read-only numpy arrays so that 100k-triangle maps stay compact.

Label sets are interned: ``letters`` lists the distinct label sets that occur (each a sorted
tuple of region names, the empty tuple for free space) and ``letter_of[t]`` indexes it.  The
automaton stage evaluates its guards over exactly these letters.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from tlmpc.base.content import ContentEquality
from tlmpc.mission.model import Polygon

IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Abstraction(ContentEquality):
    """Triangles as states, shared edges as transitions, label sets as observations.

    ``triangles[t]`` holds vertex indices counter-clockwise; ``neighbors[t, i]`` is the
    triangle across the edge opposite vertex ``i`` (``-1`` at the boundary or a hole).
    """

    vertices: FloatArray  # (n, 2)
    triangles: IntArray  # (m, 3), counter-clockwise
    neighbors: IntArray  # (m, 3), -1 for none
    letter_of: IntArray  # (m,), index into letters
    letters: tuple[tuple[str, ...], ...]
    start: int
    component: IntArray  # (m,), connected component id
    regions: Mapping[str, Polygon]
    stats: Mapping[str, Any] = field(default_factory=dict)

    @property
    def num_triangles(self) -> int:
        """Number of states of D."""
        return int(self.triangles.shape[0])

    def labels(self, triangle: int) -> tuple[str, ...]:
        """Sorted names of the regions containing ``triangle``."""
        return self.letters[int(self.letter_of[triangle])]

    def corners(self, triangle: int) -> FloatArray:
        """The (3, 2) vertex coordinates of ``triangle``, counter-clockwise."""
        corners: FloatArray = self.vertices[self.triangles[triangle]]
        return corners


def triangle_inradius(corners: FloatArray) -> float:
    """The radius of the largest disk inside the triangle with these (3, 2) corners: twice its
    area over its perimeter (0 for a degenerate one)."""
    (ax, ay), (bx, by), (cx, cy) = corners.tolist()
    area2 = abs((bx - ax) * (cy - ay) - (by - ay) * (cx - ax))
    perimeter = (
        math.hypot(bx - ax, by - ay) + math.hypot(cx - bx, cy - by) + math.hypot(ax - cx, ay - cy)
    )
    return area2 / perimeter if perimeter > 0.0 else 0.0
