"""Triangle geometry for the controllers: facets, outward normals, heights, barycentrics.

Facet ``i`` is the edge opposite vertex ``i`` (the same convention as ``neighbors``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tlmpc.abstraction.model import FloatArray

#: A plane vector: a numpy array or a pair of floats.
VectorLike = Sequence[float] | FloatArray


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


#: Ulps of the largest coordinate a length measured from absolute coordinates may carry.
COORDINATE_ULPS = 8


def coordinate_rounding(points: FloatArray) -> float:
    """The rounding of a length measured from the absolute coordinates of ``points``: a
    height (a facet's offset less a dot product with the opposite vertex), a signed distance
    of a point to a facet, a width along a unit direction (the difference of two dot
    products).  Each dot product rounds by a few ulps of the largest coordinate whatever the
    length, so two evaluations in a different order (vector by vector, or a matrix product)
    differ by that much, and a point snapped onto a facet lies off it by as much: for a
    triangle of size 1e-8 at 4.5 from the origin, about 1e-7 of its size.  The bound is
    8 ε |x|∞, ε the double precision epsilon."""
    return COORDINATE_ULPS * float(np.finfo(np.float64).eps) * float(np.abs(points).max())


def triangle_geometry(vertices: FloatArray) -> TriangleGeometry:
    """Geometry of a counter-clockwise triangle.

    Computed on Python floats: a plan's steps call this thousands of times and numpy's
    per-call overhead on 2-vectors was most of the control stage.  The operations are the
    definition's (a 2-vector's norm is sqrt(x·x) and a dot of two is a0 b0 + a1 b1, in that
    order), each rounded once as IEEE prescribes, so the values are the same on every
    machine; numpy's BLAS may fuse a multiply and an add where the processor can, so the array
    code agrees with them to a few units in the last place (tests compare).
    """
    v = np.asarray(vertices, dtype=np.float64)
    corners = v.tolist()
    normals: list[list[float]] = []
    offsets: list[float] = []
    heights: list[float] = []
    for i in range(3):
        ax, ay = corners[(i + 1) % 3]
        bx, by = corners[(i + 2) % 3]
        # outward for a counter-clockwise triangle: (edge_y, -edge_x)
        nx, ny = by - ay, -(bx - ax)
        length = math.sqrt(nx * nx + ny * ny)
        if not 0.0 < length < math.inf:
            return _triangle_geometry_arrays(v)  # degenerate: numpy's nan/inf semantics
        nx, ny = nx / length, ny / length
        offset = nx * ax + ny * ay
        px, py = corners[i]
        normals.append([nx, ny])
        offsets.append(offset)
        heights.append(offset - (nx * px + ny * py))
    return TriangleGeometry(
        vertices=v, normals=np.array(normals), offsets=np.array(offsets), heights=np.array(heights)
    )


def _triangle_geometry_arrays(v: FloatArray) -> TriangleGeometry:
    """:func:`triangle_geometry` on numpy arrays, for a degenerate edge: nan/inf (with
    numpy's warning) as numpy divides, where Python floats would raise."""
    normals = np.empty((3, 2))
    offsets = np.empty(3)
    heights = np.empty(3)
    for i in range(3):
        a, b = v[(i + 1) % 3], v[(i + 2) % 3]
        edge = b - a
        normal = np.array([edge[1], -edge[0]])
        normal /= np.linalg.norm(normal)
        normals[i] = normal
        offsets[i] = normal @ a
        heights[i] = offsets[i] - normal @ v[i]
    return TriangleGeometry(vertices=v, normals=normals, offsets=offsets, heights=heights)


def affine_law(vertices: FloatArray, velocities: FloatArray) -> tuple[FloatArray, FloatArray]:
    """K, g with K v_i + g = w_i for the three vertices (the unique affine interpolant).

    Solved in the triangle's own frame (centred, unit size): in map coordinates the system
    mixes the triangle's size with its distance from the origin and loses digits far out.
    The frame is computed on Python floats with numpy's operations in numpy's order (the
    mean sums the rows first to last), so the system is bit for bit the array code's.
    """
    frame = _frame(vertices)
    if frame is None:
        return _affine_law_arrays(np.asarray(vertices, dtype=np.float64), velocities)
    solution = np.asarray(np.linalg.solve(np.array(frame[1]), velocities), dtype=np.float64)
    return _law(solution, frame[0])


def affine_laws(
    vertices: Sequence[FloatArray], velocities: Sequence[FloatArray]
) -> list[tuple[FloatArray, FloatArray]]:
    """:func:`affine_law` of each triangle and its vertex velocities, bit for bit: the frames
    on Python floats as there, the systems solved by one call of ``np.linalg.solve`` on their
    stack (LAPACK's solve of each system, as for one; numpy's per-call cost was most of the
    time for a plan of thousands of steps)."""
    frames = [_frame(corners) for corners in vertices]
    systems = [frame[1] for frame in frames if frame is not None]
    framed = [w for w, frame in zip(velocities, frames, strict=True) if frame is not None]
    solutions = (
        np.asarray(np.linalg.solve(np.array(systems), np.array(framed)), dtype=np.float64)
        if systems
        else np.zeros((0, 3, 2))
    )
    laws: list[tuple[FloatArray, FloatArray]] = []
    solved = iter(solutions)
    for corners, w, frame in zip(vertices, velocities, frames, strict=True):
        if frame is None:  # solved on its own, with numpy's nan/inf
            laws.append(_affine_law_arrays(np.asarray(corners, dtype=np.float64), w))
        else:
            laws.append(_law(next(solved), frame[0]))
    return laws


_Frame = tuple[tuple[float, float, float], list[list[float]]]


def _frame(vertices: FloatArray) -> _Frame | None:
    """The triangle's frame (centre x, y and size) and its system in that frame, on Python
    floats; None for a point-like or non-finite triangle."""
    (x0, y0), (x1, y1), (x2, y2) = np.asarray(vertices, dtype=np.float64).tolist()
    cx, cy = (x0 + x1 + x2) / 3, (y0 + y1 + y2) / 3
    dx0, dy0, dx1, dy1, dx2, dy2 = x0 - cx, y0 - cy, x1 - cx, y1 - cy, x2 - cx, y2 - cy
    size = max(abs(dx0), abs(dy0), abs(dx1), abs(dy1), abs(dx2), abs(dy2))
    if not (math.isfinite(cx) and math.isfinite(cy) and 0.0 < size < math.inf):
        return None
    system = [
        [dx0 / size, dy0 / size, 1.0],
        [dx1 / size, dy1 / size, 1.0],
        [dx2 / size, dy2 / size, 1.0],
    ]
    return (cx, cy, size), system


def _law(solution: FloatArray, frame: tuple[float, float, float]) -> tuple[FloatArray, FloatArray]:
    """K, g in map coordinates from the solution in the triangle's frame."""
    cx, cy, size = frame
    gain: FloatArray = np.ascontiguousarray(solution[:2].T / size)
    offset: FloatArray = solution[2] - gain @ np.array([cx, cy])
    return gain, offset


def _affine_law_arrays(
    vertices: FloatArray, velocities: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """:func:`affine_law` on numpy arrays, for a point-like or non-finite triangle: numpy's
    nan/inf (with its warning) where Python floats would raise or differ."""
    center = vertices.mean(axis=0)
    size = float(np.abs(vertices - center).max())
    local = (vertices - center) / size
    system = np.hstack([local, np.ones((3, 1))])
    solution = np.asarray(np.linalg.solve(system, velocities), dtype=np.float64)
    gain: FloatArray = np.ascontiguousarray(solution[:2].T / size)
    offset: FloatArray = solution[2] - gain @ center
    return gain, offset


def largest_of(values: list[float]) -> float:
    """``max(values)`` as numpy's ``max`` gives it: nan when any value is nan (Python's
    ``max`` answers according to where the nan stands)."""
    if any(map(math.isnan, values)):  # (value != value, in C: called per step and matrix)
        return math.nan
    return max(values)


def half_plane_feasible(normals: Sequence[VectorLike]) -> bool:
    """True when some w has a·w > 0 for every a in ``normals`` (cones intersect).

    The normals must fit in an open half-plane: their directions span less than 180°.
    """
    if len(normals) <= 1:
        return True
    angles = sorted(math.atan2(a[1], a[0]) for a in normals)
    if any(angle != angle for angle in angles):
        return False  # a nan direction: numpy's largest gap is nan, never wide enough
    angles.append(angles[0] + 2 * math.pi)
    widest = max(after - before for before, after in itertools.pairwise(angles))
    return widest > math.pi + 1e-9


def best_push(normals: Sequence[VectorLike], max_speed: float) -> float:
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
    return max(min(float(np.asarray(a) @ u) for a in normals) * max_speed for u in directions)
