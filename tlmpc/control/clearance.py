"""Which label boundaries of the mesh lie on a region's own boundary.

The planner's mesh is labelled by the planning layout's shapes, not always by the regions
themselves (:mod:`tlmpc.abstraction.layout`): a goal labels its *core* (the region eroded by
the goal depth) and, with a margin, an avoided region labels its grown shape.  A mesh vertex
on the boundary of such a shape is already that far inside (or outside) the region itself, so
a path through it keeps the verifier's robustness (the distance to the nearest boundary that
would change the verdict) at that depth.  A vertex on the boundary of a region that labels its
own shape (a point robot's avoided region without margin, a region of both polarities, a goal
with ``goal_depth: 0``) is not: a path through it grazes the region and its robustness
vanishes.  Only those *exposed* vertices need the channel's label insets
(:mod:`tlmpc.control.channel`).

Read from the mesh and the regions alone (no task): a vertex on a label boundary is exposed
when it lies within :data:`TOUCH` of the mesh's extent of the boundary of a region that labels
a triangle around it (a core's corner that happens to lie on such a region's edge is exposed
too, which only keeps an inset that was not needed).
"""

from __future__ import annotations

from collections.abc import Collection, Iterable

import numpy as np
import shapely

from tlmpc.abstraction.model import Abstraction

#: A vertex "lies on" a region's boundary within this fraction of the mesh's extent: far
#: below any goal depth or margin, far above the snapping grid (a billionth of the extent).
TOUCH = 1e-6


def label_boundary(abstraction: Abstraction) -> list[bool]:
    """Per mesh vertex: is it on a label boundary (do the triangles around it not all share
    a label)?  The candidates :func:`exposed_vertices` narrows."""
    letters = np.repeat(abstraction.letter_of, 3)  # each corner's triangle's letter
    count = len(abstraction.vertices)
    lowest = np.full(count, np.iinfo(np.int64).max)
    highest = np.full(count, -1)
    np.minimum.at(lowest, abstraction.triangles.reshape(-1), letters)
    np.maximum.at(highest, abstraction.triangles.reshape(-1), letters)
    boundary: list[bool] = (lowest != highest).tolist()
    return boundary


def exposed_vertices(
    abstraction: Abstraction,
    candidates: Iterable[int],
    relevant: Collection[str] | None = None,
) -> frozenset[int]:
    """Those of ``candidates`` (mesh vertices on a label boundary) that lie on the boundary
    of a region itself (see the module doc); with ``relevant``, of one of those regions only
    (the task's propositions: the boundary of a region the task does not name never decides
    the verdict)."""
    chosen = np.asarray(sorted(set(candidates)), dtype=np.int64)
    if len(chosen) == 0 or not abstraction.regions:
        return frozenset()
    # the regions that label a triangle around a candidate: only their edges are measured
    around = np.isin(abstraction.triangles, chosen).any(axis=1)
    letters = np.unique(abstraction.letter_of[around]).tolist()
    names = sorted(
        {
            name
            for k in letters
            for name in abstraction.letters[k]
            if relevant is None or name in relevant
        }
    )
    rings = [
        np.asarray(abstraction.regions[name], dtype=np.float64).reshape(-1, 2)
        for name in names
        if name in abstraction.regions
    ]
    rings = [ring for ring in rings if len(ring) >= 2]
    if not rings:
        return frozenset()
    vertices = abstraction.vertices
    extent = float(np.ptp(vertices, axis=0).max()) if len(vertices) > 1 else 0.0
    # A tree of the regions' closed boundaries answers "within TOUCH" per point in about
    # log(edges) instead of measuring every point against every edge (a map of thousands of
    # regions has tens of thousands of edges).
    closed = [np.vstack([ring, ring[:1]]) for ring in rings]
    owner = np.repeat(np.arange(len(closed)), [len(ring) for ring in closed])
    boundaries = shapely.linestrings(np.concatenate(closed), indices=owner)
    tree = shapely.STRtree(boundaries)
    found = tree.query(
        shapely.points(vertices[chosen]), predicate="dwithin", distance=TOUCH * extent
    )
    near = np.zeros(len(chosen), dtype=bool)
    near[found[0]] = True
    return frozenset(chosen[near].tolist())
