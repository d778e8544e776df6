"""Local refinement where a path touches a triangle and turns back: split an edge at a point.

A plan cannot leave a triangle by the edge it entered by (an affine field cannot), so a path
that only needs to touch a triangle ``t`` (a goal's core, say) from its neighbour ``n`` across
their shared edge ``e`` has to cross ``t`` and leave it by another edge, far from where it came
in.  Splitting ``e`` at a point ``p`` and both triangles with it (``t`` into two halves by the
segment from ``p`` to its opposite corner, ``n`` likewise) lets the robot enter one half of
``t`` near ``p``, cross into the other half by the new spoke near ``p`` and leave by the other
half of ``e``: the turn happens around ``p``, with no bounce.

The mesh stays conforming (every edge of the two old triangles not on ``e`` keeps its single
neighbour, which now faces one of the halves), every half keeps its triangle's label
(it lies inside it: observation preservation holds by construction) and component.  The
first half of each triangle keeps its index, the second is appended, so every other triangle
keeps its index and every old vertex its id; ``p`` is appended to the vertices.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray
from tlmpc.abstraction.refine import with_splits
from tlmpc.abstraction.starts import cells_in

#: A split point keeps at least this fraction of its edge's length from both ends: the halves
#: stay as wide as a quarter of the old triangles' heights allow (no needle for the fields).
EDGE_MARGIN = 0.2


def split_edges(
    abstraction: Abstraction,
    splits: Sequence[tuple[int, int, float]],
    start_point: tuple[float, float],
) -> Abstraction:
    """``abstraction`` with each ``(triangle, edge, u)`` of ``splits`` applied: the edge opposite
    local corner ``edge`` of ``triangle`` (from corner ``edge + 1`` to ``edge + 2``) is split at
    the fraction ``u`` along it (clamped to :data:`EDGE_MARGIN` from its ends), and the
    triangle and its neighbour across it are each split in two through that point.

    A split whose triangle or neighbour an earlier split of the list already cut, or whose
    edge has no neighbour (a wall), is skipped; so is one whose triangles hold the start point
    (the start keeps its triangle).  With no split left, ``abstraction`` itself is returned.
    """
    starts = {c.triangle for c in _start_cells(abstraction, start_point)}
    touched: set[int] = set(starts)
    chosen: list[tuple[int, int, float, int]] = []
    for triangle, edge, u in splits:
        neighbour = int(abstraction.neighbors[triangle, edge])
        if neighbour < 0 or triangle in touched or neighbour in touched:
            continue
        if _thin_halves(abstraction, int(triangle), int(edge), u, neighbour):
            continue
        touched.update((triangle, neighbour))
        chosen.append(
            (int(triangle), int(edge), min(1 - EDGE_MARGIN, max(EDGE_MARGIN, u)), neighbour)
        )
    if not chosen:
        return abstraction
    count = abstraction.num_triangles
    extra = 2 * len(chosen)
    tri = np.vstack([abstraction.triangles, np.zeros((extra, 3), dtype=np.int64)])
    nbr = np.vstack([abstraction.neighbors, np.zeros((extra, 3), dtype=np.int64)])
    letter_of = np.concatenate([abstraction.letter_of, np.zeros(extra, dtype=np.int64)])
    component = np.concatenate([abstraction.component, np.zeros(extra, dtype=np.int64)])
    points: list[FloatArray] = []
    next_vertex = len(abstraction.vertices)
    next_triangle = count
    for triangle, edge, u, neighbour in chosen:
        corners = tri[triangle]
        a, b = int(corners[(edge + 1) % 3]), int(corners[(edge + 2) % 3])
        start, end = abstraction.vertices[a], abstraction.vertices[b]
        points.append(start + u * (end - start))
        p = next_vertex
        next_vertex += 1
        other_edge = int(np.flatnonzero(nbr[neighbour] == triangle)[0])
        second_t, second_n = next_triangle, next_triangle + 1
        next_triangle += 2
        # t = (c, a, b) rotated so that edge is opposite c: halves (c, a, p) and (c, p, b).
        # n = (d, b, a) likewise: halves (d, b, p) and (d, p, a).  The half of t on a's side
        # meets the half of n on a's side across (a, p), and so on.
        _split_one(
            tri, nbr, letter_of, component, triangle, edge, p, second_t, (second_n, neighbour)
        )
        _split_one(
            tri, nbr, letter_of, component, neighbour, other_edge, p, second_n, (second_t, triangle)
        )
    return with_splits(
        abstraction,
        np.vstack([abstraction.vertices, np.asarray(points, dtype=np.float64)]),
        (tri, nbr, letter_of, component),
        start_point,
        counter="split_for_touches",
        count=len(chosen),
    )


def _split_one(
    tri: Any,
    nbr: Any,
    letter_of: Any,
    component: Any,
    t: int,
    edge: int,
    p: int,
    second: int,
    across: tuple[int, int],
) -> None:
    """Split triangle ``t`` through ``p`` on its edge opposite local corner ``edge``: ``t``
    keeps the half (c, a, p) on the edge's first end a, ``second`` takes (c, p, b).

    ``across`` names the triangles across the two halves of the split edge once both sides
    are split: (the one facing (a, p), the one facing (p, b)).  Corners are read before any
    write; ``nbr`` of the outer neighbour that faced t across (b, c) is re-pointed to
    ``second``.
    """
    c = int(tri[t, edge])
    a = int(tri[t, (edge + 1) % 3])
    b = int(tri[t, (edge + 2) % 3])
    outer_ca = int(nbr[t, (edge + 2) % 3])  # across (c, a): opposite b
    outer_bc = int(nbr[t, (edge + 1) % 3])  # across (b, c): opposite a
    facing_ap, facing_pb = across
    # (c, a, p): opposite c is (a, p), opposite a is (p, c) -> second, opposite p is (c, a)
    tri[t] = (c, a, p)
    nbr[t] = (facing_ap, second, outer_ca)
    # (c, p, b): opposite c is (p, b), opposite p is (b, c), opposite b is (c, p) -> t
    tri[second] = (c, p, b)
    nbr[second] = (facing_pb, outer_bc, t)
    letter_of[second] = letter_of[t]
    component[second] = component[t]
    if outer_bc >= 0:
        nbr[outer_bc, nbr[outer_bc] == t] = second


#: A half whose smallest height is below this fraction of its longest edge is a needle: no
#: split makes one (the fields of needles only keep the vertex conditions, and a sliver's
#: half can be crossed in a time the verifier's samples do not resolve).
NEEDLE = 0.05


def _thin_halves(abstraction: Abstraction, t: int, edge: int, u: float, n: int) -> bool:
    """Whether splitting ``t``'s edge opposite corner ``edge`` at ``u`` (clamped as
    :func:`split_edges` clamps it) would make a needle of one of the four halves."""
    u = min(1 - EDGE_MARGIN, max(EDGE_MARGIN, u))
    corners = abstraction.triangles[t].tolist()
    c = abstraction.vertices[corners[edge]]
    a = abstraction.vertices[corners[(edge + 1) % 3]]
    b = abstraction.vertices[corners[(edge + 2) % 3]]
    d = abstraction.vertices[next(v for v in abstraction.triangles[n].tolist() if v not in corners)]
    p = a + u * (b - a)
    return any(_needle(x, y, z) for x, y, z in ((c, a, p), (c, p, b), (d, b, p), (d, p, a)))


def _needle(x: FloatArray, y: FloatArray, z: FloatArray) -> bool:
    area2 = abs(float((y[0] - x[0]) * (z[1] - x[1]) - (y[1] - x[1]) * (z[0] - x[0])))
    longest = max(float(np.hypot(*(y - x))), float(np.hypot(*(z - y))), float(np.hypot(*(x - z))))
    # smallest height = twice the area over the longest edge
    return longest == 0.0 or area2 / longest < NEEDLE * longest


def _start_cells(abstraction: Abstraction, start_point: tuple[float, float]) -> list[Any]:
    return list(
        cells_in(
            abstraction.vertices,
            abstraction.triangles,
            abstraction.neighbors,
            abstraction.letter_of,
            start_point,
        )
    )
