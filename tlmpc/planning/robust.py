"""Which moves and stays the controllers can realise under a disturbance, from the angles.

A step in triangle t leaving by edge i needs, at each corner, a velocity within max_speed
that pushes along the normals of the facets through it (inward on the kept ones, outward on
the exit) by more than the disturbance d. In the plane that best push is, with a the
triangle's angle at the corner (docs/control.md):

* max_speed * sin(a / 2) at the corner opposite the exit (both its facets kept) and at
  every corner of a stay;
* max_speed * cos(a / 2) at the two corners on the exit edge (one facet kept, one crossed).

So a move or stay is *realisable* for the ratio r = d / max_speed (plus the controllers'
stated tolerance) exactly when those values exceed r. The planner is first run on every move;
when its plan has a step that is not realisable (a needle, or a corner too sharp for the
disturbance), it runs again on the realisable ones only, where the mesh has them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.planning.model import Witness

BoolArray = npt.NDArray[np.bool_]
#: A plane vector as two floats.
Vector = tuple[float, float]

#: The controllers' re-check demands each push with this much to spare, relative to
#: max_speed (control.synthesize.RECHECK_TOLERANCE), and a little more for rounding here.
TOLERANCE = 2e-9


def best_direction(normals: Sequence[Vector]) -> tuple[float, Vector]:
    """The unit u maximising min_k a_k·u over unit normals a_k, and that minimum: the
    *corner push* of a vertex whose rows are the a_k (in units of max_speed), the one
    implementation of it (the control stage's vertex velocities, the convex cells' widths).

    The maximiser of a minimum of linear functions over the unit disc points along one normal
    or along the bisector of two (the optimum of a two-dimensional max-min sits where at most
    two constraints are active), so those directions are the only candidates. The bisector of
    two nearly opposite normals (a sliver corner) is taken perpendicular to their difference,
    which keeps its digits where their sum would cancel them. Only the bisector on the normals'
    side is a candidate: where no open half-plane holds the normals (the true maximum is at
    most 0, no velocity pushes along all of them) the value may be below that maximum, but it
    is at most 0 all the same; wherever the maximum is positive it is the maximum.
    """
    if not normals:
        return 1.0, (1.0, 0.0)
    candidates: list[Vector] = [(float(a[0]), float(a[1])) for a in normals]
    for i, (ax, ay) in enumerate(normals):
        for bx, by in normals[i + 1 :]:
            dx, dy = ax - bx, ay - by
            length = math.hypot(dx, dy)
            if length == 0.0:
                continue
            ux, uy = -dy / length, dx / length  # perpendicular to a - b: a·u = b·u
            if ax * ux + ay * uy < 0.0:
                ux, uy = -ux, -uy
            candidates.append((ux, uy))
    best_value, best = -math.inf, candidates[0]
    for ux, uy in candidates:
        value = min(ax * ux + ay * uy for ax, ay in normals)
        if value > best_value:
            best_value, best = value, (ux, uy)
    return best_value, best


def corner_angles(abstraction: Abstraction, triangles: IntArray | None = None) -> FloatArray:
    """(m, 3): each triangle's interior angle at each corner, in radians (atan2 of the cross
    and dot products of the two edges: accurate for slivers, where acos of a cosine is not).
    With ``triangles``, the rows of those triangles only (each the same floats)."""
    chosen = abstraction.triangles if triangles is None else abstraction.triangles[triangles]
    corners = abstraction.vertices[chosen]  # (m, 3, 2)
    angles = np.empty(corners.shape[:2])
    for i in range(3):
        u = corners[:, (i + 1) % 3] - corners[:, i]
        w = corners[:, (i + 2) % 3] - corners[:, i]
        cross = np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0])
        dot = u[:, 0] * w[:, 0] + u[:, 1] * w[:, 1]
        angles[:, i] = np.arctan2(cross, dot)
    return angles


def step_widths(
    abstraction: Abstraction, triangles: IntArray | None = None
) -> tuple[FloatArray, FloatArray]:
    """(m, 3) and (m,): the largest disturbance ratio (d / max_speed) each move (leave t by
    edge i) and each stay rejects, before the controllers' tolerance: the smallest push of
    its corners (sin(a / 2) where both facets are kept, cos(a / 2) on the exit edge); with
    ``triangles``, the rows of those triangles only."""
    half = corner_angles(abstraction, triangles) / 2.0
    kept = np.sin(half)  # a corner held on both facets
    crossing = np.cos(half)  # a corner on the exit edge
    moves = np.empty(kept.shape)
    for i in range(3):
        moves[:, i] = np.minimum(
            kept[:, i], np.minimum(crossing[:, (i + 1) % 3], crossing[:, (i + 2) % 3])
        )
    stays: FloatArray = kept.min(axis=1)
    return moves, stays


def realisable(
    abstraction: Abstraction, ratio: float, triangles: IntArray | None = None
) -> tuple[BoolArray, BoolArray]:
    """(m, 3) moves (leave t by edge i) and (m,) stays realisable under the disturbance
    ``ratio`` x max_speed (with the controllers' tolerance): their width exceeds it; with
    ``triangles``, the rows of those triangles only."""
    need = ratio + TOLERANCE
    moves, stays = step_widths(abstraction, triangles)
    return np.asarray(moves > need, dtype=bool), np.asarray(stays > need, dtype=bool)


def witness_realisable(abstraction: Abstraction, witness: Witness, ratio: float) -> bool:
    """True when every step of ``witness`` is realisable under ``ratio`` x max_speed (a
    vertex passage only without a disturbance: no law here reaches a point under one)."""
    path = [*witness.prefix, *witness.cycle]
    # Only the path's triangles (a few thousand of a million-triangle mesh): row k of the
    # tables is triangle on_path[k].
    on_path = np.unique(np.asarray(path, dtype=np.int64))
    moves, stays = realisable(abstraction, ratio, on_path)
    row = dict(zip(on_path.tolist(), range(len(on_path)), strict=True))
    passages = dict(witness.passages)
    for index, triangle in enumerate(path):
        if witness.is_stay and index == len(path) - 1:
            if not stays[row[triangle]]:
                return False
            continue
        following = path[index + 1] if index + 1 < len(path) else witness.cycle[0]
        if index in passages:
            if ratio > 0.0:
                return False
            continue
        edges = np.flatnonzero(abstraction.neighbors[triangle] == following)
        if len(edges) != 1 or not moves[row[triangle], int(edges[0])]:
            return False
    return True
