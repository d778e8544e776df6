"""The exact trajectory of a cell step (:class:`tlmpc.control.model.CellField`).

Inside a piece (one triangle of the cell) the law u = K x + g is solved exactly with the
matrix exponential of its augmented matrix, as for a triangle step; the piece is left where
the first of its facets is crossed (bracketed on a grid of exact states, refined by regula
falsi on the flow). Across an inner facet the next piece takes over; across the interface the
step ends; across a kept side the field is wrong (C031). A move's robot leaves each piece
within (the largest xi·v over its corners minus xi·x) / (the flow speed), so the grid spans
that. A stay runs the radial law, whose flow is x(t) = c + exp(-kappa t) (x0 - c).
"""

from __future__ import annotations

import math

import numpy as np

from tlmpc.abstraction.model import FloatArray
from tlmpc.base.errors import SolverError, error
from tlmpc.control.geometry import coordinate_rounding, triangle_geometry
from tlmpc.control.model import EXIT, KEPT, CellField, StepController
from tlmpc.simulate.matrix import augmented, expm_small

#: Grid points per piece that bracket its exit before root finding.
GRID_POINTS = 256
#: How far outside a piece a state still counts as in it (relative to the piece's size) and
#: beyond a facet it counts as past it (relative to the piece's extent across that facet),
#: each besides the rounding of the coordinates.
SLACK = 1e-9
#: Pieces a move may cross before the simulation gives up (a field that circles is a bug).
MAX_PIECES = 100_000
#: Samples of a stay, and the contraction it is followed for.
STAY_SAMPLES = 32
STAY_CONTRACTION = 1e-6


def nearest_piece(field: CellField, point: FloatArray) -> int:
    """The piece whose smallest barycentric weight at ``point`` is largest: the one holding
    it, or the nearest to it just outside (the executor's choice of law off the pieces)."""
    piece = locate(field, point, velocity_hint=False, outside=True)
    assert piece is not None  # a cell field has a piece
    return piece


def locate(
    field: CellField, point: FloatArray, velocity_hint: bool = True, outside: bool = False
) -> int | None:
    """The piece holding ``point``: of the pieces holding it (to within :data:`SLACK` of
    their size and the rounding of the coordinates, :func:`coordinate_rounding`; every piece
    with ``outside``), the one whose smallest barycentric weight is largest, at ``point`` or,
    with ``velocity_hint``, a little ahead along the field (on a shared facet: the one the
    field enters); the first of equals; None when none holds it."""
    # A crossing snapped onto a facet lies off it by the rounding of its coordinates, which
    # on a piece of size 1e-8 far from the origin is far more than SLACK of its size.
    rounding = max(coordinate_rounding(field.vertices), coordinate_rounding(point))
    best, best_value = None, -math.inf
    for piece in range(len(field.triangles)):
        geometry = triangle_geometry(field.vertices[piece])
        weights = geometry.barycentric(point)
        scale = float(geometry.heights.max())
        lowest = float(weights.min())
        if not outside and (weights < -SLACK * max(scale, 1.0) - rounding / geometry.heights).any():
            continue
        value = lowest
        if velocity_hint:
            u = field.gains[piece] @ point + field.offsets[piece]
            ahead = point + 1e-6 * scale * u / max(float(np.linalg.norm(u)), 1e-300)
            value = float(geometry.barycentric(ahead).min())
        if value > best_value:
            best, best_value = piece, value
    return best


def cell_step(
    controller: StepController, x0: FloatArray, max_speed: float
) -> tuple[list[float], list[FloatArray], list[int], list[bool]]:
    """Times (from 0), points, triangles and crossing flags of a cell step from ``x0``."""
    field = controller.cell
    assert field is not None
    if field.direction is None:
        return _stay(controller, field, x0, max_speed)
    return _move(controller, field, x0)


def _stay(
    controller: StepController, field: CellField, x0: FloatArray, max_speed: float
) -> tuple[list[float], list[FloatArray], list[int], list[bool]]:
    assert controller.target is not None
    centre = np.asarray(controller.target, dtype=np.float64)
    kappa = -float(field.gains[0][0, 0])
    if kappa <= 0.0:
        raise SolverError(
            error("C011", f"plan step {controller.step}: the stay field does not converge")
        )
    horizon = math.log(1.0 / STAY_CONTRACTION) / kappa
    times = [float(t) for t in horizon * (np.geomspace(1.0, 1001.0, STAY_SAMPLES) - 1.0) / 1000.0][
        1:
    ]
    points = [centre + math.exp(-kappa * t) * (x0 - centre) for t in times]
    last = points[-1]
    times.append(times[-1] + max(float(np.linalg.norm(last - centre)) / max_speed, 1e-9) + 1e-9)
    points.append(centre)
    triangles = []
    for point in points:
        piece = locate(field, point, velocity_hint=False)
        triangles.append(field.triangles[piece if piece is not None else 0])
    return times, points, triangles, [False] * len(points)


def _move(
    controller: StepController, field: CellField, x0: FloatArray
) -> tuple[list[float], list[FloatArray], list[int], list[bool]]:
    assert field.direction is not None
    xi = np.asarray(field.direction)
    speed = controller.exit_speed
    piece = locate(field, x0)
    if piece is None:
        raise SolverError(
            error(
                "C031",
                f"plan step {controller.step}: the robot at ({x0[0]:.6g}, {x0[1]:.6g}) is not "
                "in the step's cell",
                hint="please report this mission; the controllers do not realise the plan",
            )
        )
    times: list[float] = []
    points: list[FloatArray] = []
    triangles: list[int] = []
    crossings: list[bool] = []
    now, x = 0.0, np.asarray(x0, dtype=np.float64)
    rounding = coordinate_rounding(field.vertices)
    for _ in range(MAX_PIECES):
        geometry = triangle_geometry(field.vertices[piece])
        # per facet: a needle's largest height would let the state run past its thin side by
        # more than the flow's bound reaches
        beyond = SLACK * geometry.heights + rounding
        centre = field.vertices[piece].mean(axis=0)
        matrix = augmented(field.gains[piece], field.gains[piece] @ centre + field.offsets[piece])
        reach = float((field.vertices[piece] @ xi).max() - xi @ x)
        horizon = max(reach, 0.0) / speed * 1.02 + 1e-12
        dt = horizon / GRID_POINTS
        step = expm_small(dt * matrix)
        state = np.array([*(x - centre), 1.0])
        offsets = geometry.offsets - geometry.normals @ centre
        previous, found = state, None
        for k in range(1, GRID_POINTS + 1):
            state = step @ previous
            heights = geometry.normals @ state[:2] - offsets
            if (heights > beyond).any():
                found = k
                break
            previous = state
        if found is None:
            raise SolverError(
                error(
                    "C010",
                    f"plan step {controller.step}: the trajectory did not leave a triangle of "
                    "its cell within the bound of its flow",
                    hint="please report this mission",
                )
            )
        # the earliest facet crossed between grid points found - 1 and found
        earliest, facet = dt, -1
        for j in range(3):

            def height(
                s: float,
                j: int = j,
                matrix: FloatArray = matrix,
                previous: FloatArray = previous,
                normals: FloatArray = geometry.normals,
                offsets: FloatArray = offsets,
            ) -> float:
                y = expm_small(s * matrix) @ previous
                return float(normals[j] @ y[:2] - offsets[j])

            if height(dt) <= 0.0:
                continue
            low, high = 0.0, dt
            if height(low) >= 0.0:
                root = 0.0
            else:
                for _ in range(80):
                    middle = 0.5 * (low + high)
                    if height(middle) < 0.0:
                        low = middle
                    else:
                        high = middle
                root = high
            if root < earliest or facet < 0:
                earliest, facet = root, j
        crossing = (found - 1) * dt + earliest
        end = (expm_small(earliest * matrix) @ previous)[:2] + centre
        # samples inside the piece: a few grid states
        for k in (GRID_POINTS // 4, GRID_POINTS // 2, 3 * GRID_POINTS // 4):
            if k < found - 1:
                inner = (np.linalg.matrix_power(step, k) @ np.array([*(x - centre), 1.0]))[:2]
                times.append(now + k * dt)
                points.append(inner + centre)
                triangles.append(field.triangles[piece])
                crossings.append(False)
        kind = field.neighbours[piece][facet]
        if kind == KEPT:
            raise SolverError(
                error(
                    "C031",
                    f"plan step {controller.step}: the field leaves its cell across a kept "
                    f"side of triangle {field.triangles[piece]} near ({end[0]:.6g}, "
                    f"{end[1]:.6g}), not through the planned interface",
                    hint="please report this mission; the controllers do not realise the plan",
                )
            )
        now += crossing
        # onto the crossed facet (the root is exact to rounding; this removes the residue)
        normal = geometry.normals[facet]
        end = end - (float(normal @ end) - float(geometry.offsets[facet])) * normal
        times.append(now)
        points.append(end)
        crossings.append(True)
        if kind == EXIT:
            following = controller.next_triangle
            triangles.append(following if following is not None else field.triangles[piece])
            return times, points, triangles, crossings
        piece = kind
        triangles.append(field.triangles[piece])
        x = end
    raise SolverError(
        error(
            "C010",
            f"plan step {controller.step}: the trajectory crossed {MAX_PIECES} triangles of its "
            "cell without leaving it",
            hint="please report this mission",
        )
    )
