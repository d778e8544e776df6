"""The triangles whose closure holds the robot's start point, decided exactly.

A start on an edge lies in two triangles, one on a vertex in every triangle around it; each
may come first in a plan.  The edges through the start are *blocked* for that triangle's
first move (see :mod:`tlmpc.planning.boundary`).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray

#: A start closer than this to an edge (relative to the triangle's height over it) may cross
#: it at once in the simulator (rounding): such an edge is blocked at t = 0 where the label
#: changes across it.
ON_EDGE_TOLERANCE = 1e-12

Exact = tuple[Fraction, Fraction]


@dataclass(frozen=True, slots=True)
class StartCell:
    """A triangle whose closure contains the start, and its edges that contain the start."""

    triangle: int
    blocked: tuple[int, ...]


def _orientation(a: Exact, b: Exact, p: Exact) -> Fraction:
    return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])


def start_cells(abstraction: Abstraction, point: tuple[float, float]) -> tuple[StartCell, ...]:
    """Every triangle containing ``point`` (decided exactly, in rationals), with blocked edges.

    An edge is blocked when it contains the point exactly, or when the point lies within
    :data:`ON_EDGE_TOLERANCE` of it and the label changes across it (rounding could make the
    robot cross it at once and skip the triangle's label).
    """
    return cells_in(
        abstraction.vertices,
        abstraction.triangles,
        abstraction.neighbors,
        abstraction.letter_of,
        point,
    )


def cells_in(
    vertices: FloatArray,
    triangles: IntArray,
    neighbors: IntArray,
    letter_of: IntArray,
    point: tuple[float, float],
) -> tuple[StartCell, ...]:
    """:func:`start_cells` on raw arrays."""
    x, y = float(point[0]), float(point[1])
    # Bounding boxes column by column (a reduction over an axis of three is several times
    # slower on a million triangles): the x extents of every triangle, the y extents only of
    # those whose x extent holds the point (no (m, 3, 2) array of corners).
    xs = vertices[:, 0][triangles]
    near = np.flatnonzero(
        (np.minimum(np.minimum(xs[:, 0], xs[:, 1]), xs[:, 2]) <= x)
        & (x <= np.maximum(np.maximum(xs[:, 0], xs[:, 1]), xs[:, 2]))
    )
    ys = vertices[:, 1][triangles[near]]
    candidates = near[
        (np.minimum(np.minimum(ys[:, 0], ys[:, 1]), ys[:, 2]) <= y)
        & (y <= np.maximum(np.maximum(ys[:, 0], ys[:, 1]), ys[:, 2]))
    ]
    p = (Fraction(x), Fraction(y))
    cells: list[StartCell] = []
    for t in candidates.tolist():
        exact = [(Fraction(float(u)), Fraction(float(v))) for u, v in vertices[triangles[t]]]
        # Edge i is opposite vertex i; a counter-clockwise triangle has every orientation
        # of an inside point non-negative.
        sides = [_orientation(exact[(i + 1) % 3], exact[(i + 2) % 3], p) for i in range(3)]
        if min(sides) < 0:
            continue
        area = _orientation(exact[0], exact[1], exact[2])
        # sides[i] / area is the distance to edge i over the height above it.  A start that
        # close to an edge may cross it at once (rounding); that matters only where the label
        # changes across it, so only such near edges are blocked (exact ones always are).
        blocked = [
            i
            for i in range(3)
            if sides[i] == 0
            or (
                sides[i] <= ON_EDGE_TOLERANCE * area
                and neighbors[t, i] >= 0
                and letter_of[neighbors[t, i]] != letter_of[t]
            )
        ]
        cells.append(StartCell(triangle=int(t), blocked=tuple(blocked)))
    return tuple(cells)
