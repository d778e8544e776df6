"""Triangle geometry for the controllers: facets, outward normals, heights, barycentrics.

Facet ``i`` is the edge opposite vertex ``i`` (the same convention as ``neighbors``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tlmpc.abstraction.model import FloatArray


@dataclass(frozen=True, slots=True)
class TriangleGeometry:
    """Outward unit normals ``n[i]``, offsets ``c[i]`` (n_i·x = c_i on facet i), heights."""

    vertices: FloatArray  # (3, 2) counter-clockwise
    normals: FloatArray  # (3, 2)
    offsets: FloatArray  # (3,)
    heights: FloatArray  # (3,)

    def barycentric(self, point: FloatArray) -> FloatArray:
        """λ_i(x) = (c_i - n_i·x) / h_i; they sum to one."""
        return (self.offsets - self.normals @ point) / self.heights

    def incenter(self) -> FloatArray:
        """The point farthest from the three edges."""
        lengths = np.array(
            [
                np.linalg.norm(self.vertices[(i + 1) % 3] - self.vertices[(i + 2) % 3])
                for i in range(3)
            ]
        )
        return (lengths[:, None] * self.vertices).sum(axis=0) / lengths.sum()  # type: ignore[no-any-return]


def triangle_geometry(vertices: FloatArray) -> TriangleGeometry:
    """Geometry of a counter-clockwise triangle."""
    v = np.asarray(vertices, dtype=np.float64)
    normals = np.empty((3, 2))
    offsets = np.empty(3)
    heights = np.empty(3)
    for i in range(3):
        a, b = v[(i + 1) % 3], v[(i + 2) % 3]
        edge = b - a
        normal = np.array([edge[1], -edge[0]])  # outward for a counter-clockwise triangle
        normal /= np.linalg.norm(normal)
        normals[i] = normal
        offsets[i] = normal @ a
        heights[i] = offsets[i] - normal @ v[i]
    return TriangleGeometry(vertices=v, normals=normals, offsets=offsets, heights=heights)


def affine_law(vertices: FloatArray, velocities: FloatArray) -> tuple[FloatArray, FloatArray]:
    """K, g with K v_i + g = w_i for the three vertices (the unique affine interpolant).

    Solved in the triangle's own frame (centred, unit size): in map coordinates the system
    mixes the triangle's size with its distance from the origin and loses digits far out.
    """
    center = vertices.mean(axis=0)
    size = float(np.abs(vertices - center).max())
    local = (vertices - center) / size
    system = np.hstack([local, np.ones((3, 1))])
    solution = np.asarray(np.linalg.solve(system, velocities), dtype=np.float64)
    gain: FloatArray = np.ascontiguousarray(solution[:2].T / size)
    offset: FloatArray = solution[2] - gain @ center
    return gain, offset


def half_plane_feasible(normals: list[FloatArray]) -> bool:
    """True when some w has a·w > 0 for every a in ``normals`` (cones intersect).

    The normals must fit in an open half-plane: their directions span less than 180°.
    """
    if len(normals) <= 1:
        return True
    angles = np.sort(np.array([np.arctan2(a[1], a[0]) for a in normals]))
    gaps = np.diff(np.concatenate([angles, [angles[0] + 2 * np.pi]]))
    return bool(gaps.max() > np.pi + 1e-9)


def best_push(normals: list[FloatArray], max_speed: float) -> float:
    """max over |w| <= max_speed of min_k a_k·w, for unit normals a_k (exact, in the plane).

    The largest speed a vertex velocity can guarantee along every normal at once: a disturbance
    bounded by less than this can be rejected there.  The maximiser of a minimum of linear
    functions over a disc points along one normal or along the bisector of two, so those
    directions are the only candidates.
    """
    if not normals:
        return max_speed
    directions = [np.asarray(a, dtype=np.float64) for a in normals]
    for i, a in enumerate(normals):
        for b in normals[i + 1 :]:
            bisector = np.asarray(a) + np.asarray(b)
            length = float(np.linalg.norm(bisector))
            if length > 1e-12:
                directions.append(bisector / length)
    return max(
        min(float(np.asarray(a) @ u) for a in normals) * max_speed for u in directions
    )
