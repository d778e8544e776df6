"""Local refinement for U-turns: split a triangle into a fan of three around an interior point.

An affine field cannot enter a triangle and leave it through the same edge (the no-bounce
rule), so a robot cannot turn around inside one triangle.  Splitting triangle ``t`` with
corners ``v0, v1, v2`` around an interior point ``p`` gives the sub-triangles
``S_i = (p, v_{i+1}, v_{i+2})``: each keeps one outer edge of ``t`` (so every outer neighbour
still shares a whole edge, the mesh stays conforming) and shares its two spokes with the other
two.  A robot entering ``S_i`` through the outer edge can circle ``S_i -> S_{i+1} -> S_{i+2}
-> S_i`` and leave through the same outer edge without ever bouncing.  All three keep ``t``'s
label (they lie inside ``t``), so observation preservation holds by construction.

``S_0`` keeps the index ``t``; ``S_1`` and ``S_2`` are appended, so every other triangle keeps
its index.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from tlmpc.abstraction.build import locate_in
from tlmpc.abstraction.model import Abstraction, FloatArray
from tlmpc.abstraction.starts import cells_in

#: Interior points tried in turn (barycentric weights of the three corners): the centroid
#: first, others when the start point would lie on a spoke of the centroid's fan.
_SPLIT_WEIGHTS = ((1 / 3, 1 / 3, 1 / 3), (0.5, 0.25, 0.25), (0.25, 0.5, 0.25), (0.25, 0.25, 0.5))


def _on_spoke(corners: FloatArray, centre: FloatArray, point: FloatArray) -> bool:
    """True when ``point`` lies (numerically) on a segment from ``centre`` to a corner."""

    def cross(u: FloatArray, w: FloatArray) -> float:
        return float(u[0] * w[1] - u[1] * w[0])

    scale = abs(cross(corners[1] - corners[0], corners[2] - corners[0]))
    for corner in corners:
        u, w = corner - centre, point - centre
        if abs(cross(u, w)) <= 1e-9 * scale and float(np.dot(u, w)) >= 0.0:
            return True
    return False


def split_triangles(
    abstraction: Abstraction, triangles: Iterable[int], start_point: tuple[float, float]
) -> Abstraction:
    """``abstraction`` with each of ``triangles`` split into a fan of three.

    ``start_point`` is re-located on the refined mesh; the split point of the start triangle
    is chosen so that the start lies strictly inside one sub-triangle.
    """
    targets = sorted({int(t) for t in triangles})
    if not targets:
        return abstraction
    vertices = [abstraction.vertices.copy()]
    tri = np.vstack([abstraction.triangles, np.zeros((2 * len(targets), 3), dtype=np.int64)])
    nbr = np.vstack([abstraction.neighbors, np.zeros((2 * len(targets), 3), dtype=np.int64)])
    letter_of = np.concatenate(
        [abstraction.letter_of, np.repeat(abstraction.letter_of[targets], 2)]
    )
    component = np.concatenate(
        [abstraction.component, np.repeat(abstraction.component[targets], 2)]
    )
    start = np.asarray(start_point, dtype=np.float64)
    next_vertex = len(abstraction.vertices)
    next_triangle = abstraction.num_triangles
    new_points: list[FloatArray] = []
    for t in targets:
        corners = abstraction.vertices[abstraction.triangles[t]]
        centre = corners.mean(axis=0)
        for weights in _SPLIT_WEIGHTS:
            centre = np.asarray(weights) @ corners
            if not _on_spoke(corners, centre, start):
                break
        new_points.append(centre)
        p = next_vertex
        next_vertex += 1
        v = tri[t].copy()
        outer = nbr[t].copy()
        subs = (t, next_triangle, next_triangle + 1)
        next_triangle += 2
        for i in range(3):
            s = subs[i]
            tri[s] = (p, v[(i + 1) % 3], v[(i + 2) % 3])
            nbr[s] = (outer[i], subs[(i + 1) % 3], subs[(i + 2) % 3])
            n = int(outer[i])
            if n >= 0:
                # The outer neighbour pointed at t across this edge; it now faces S_i.
                nbr[n, nbr[n] == t] = s
    vertices.append(np.asarray(new_points, dtype=np.float64).reshape(-1, 2))
    return with_splits(
        abstraction,
        np.vstack(vertices),
        (tri, nbr, letter_of, component),
        start_point,
        counter="split_for_u_turns",
        count=len(targets),
    )


def with_splits(
    abstraction: Abstraction,
    vertices: FloatArray,
    arrays: tuple[Any, Any, Any, Any],
    start_point: tuple[float, float],
    *,
    counter: str,
    count: int,
) -> Abstraction:
    """``abstraction`` with its triangles split: the new ``vertices`` and (triangles,
    neighbours, letters, components) arrays, made read-only, its start cell found again, and
    ``count`` more splits in the statistic ``counter``."""
    tri, nbr, letter_of, component = arrays
    cells = cells_in(vertices, tri, nbr, letter_of, start_point)
    new_start = min(c.triangle for c in cells) if cells else locate_in(vertices, tri, start_point)
    for array in (vertices, tri, nbr, letter_of, component):
        array.setflags(write=False)
    stats: dict[str, Any] = dict(abstraction.stats)
    stats.update(
        {
            "vertices": len(vertices),
            "triangles": len(tri),
            "edges": int((nbr >= 0).sum() // 2),
            counter: int(stats.get(counter, 0)) + count,
        }
    )
    return Abstraction(
        vertices=vertices,
        triangles=tri,
        neighbors=nbr,
        letter_of=letter_of,
        letters=abstraction.letters,
        start=new_start,
        component=component,
        regions=abstraction.regions,
        stats=stats,
    )
