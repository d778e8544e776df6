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
when it lies within :data:`TOUCH` of the mesh's extent of some region's own boundary (of any
region: a core's corner that happens to lie on another region's edge is exposed too, which
only keeps an inset that was not needed).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray

#: A vertex "lies on" a region's boundary within this fraction of the mesh's extent: far
#: below any goal depth or margin, far above the snapping grid (a billionth of the extent).
TOUCH = 1e-6


def exposed_vertices(abstraction: Abstraction, candidates: Iterable[int]) -> frozenset[int]:
    """Those of ``candidates`` (mesh vertices on a label boundary) that lie on the boundary
    of a region itself (see the module doc)."""
    chosen = sorted(set(candidates))
    if not chosen or not abstraction.regions:
        return frozenset()
    vertices = abstraction.vertices
    extent = float(np.ptp(vertices, axis=0).max()) if len(vertices) > 1 else 0.0
    tolerance = TOUCH * extent
    points = vertices[np.asarray(chosen, dtype=np.int64)]
    near = np.zeros(len(chosen), dtype=bool)
    for name in sorted(abstraction.regions):
        ring = np.asarray(abstraction.regions[name], dtype=np.float64).reshape(-1, 2)
        if len(ring) >= 2:
            near |= _to_ring(points, ring) <= tolerance
    return frozenset(v for v, hit in zip(chosen, near.tolist(), strict=True) if hit)


def _to_ring(points: FloatArray, ring: FloatArray) -> FloatArray:
    """(P,): each point's distance to the closed polygonal ring through ``ring``'s corners."""
    end = np.roll(ring, -1, axis=0)
    edge = end - ring  # (E, 2)
    squared = np.maximum(np.einsum("ij,ij->i", edge, edge), 1e-300)
    rel = points[:, None, :] - ring[None, :, :]  # (P, E, 2)
    u = np.clip(np.einsum("pej,ej->pe", rel, edge) / squared, 0.0, 1.0)
    gap = rel - u[:, :, None] * edge[None, :, :]
    distance: FloatArray = np.sqrt(np.einsum("pej,pej->pe", gap, gap)).min(axis=1)
    return distance
