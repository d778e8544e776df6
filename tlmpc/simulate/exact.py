"""Stage 7: the exact closed-loop trajectory of the plan's affine fields.

Within a step, x' = Kx + g is solved exactly with the matrix exponential of the augmented
matrix M = [[K, g], [0, 0]]: [x(t); 1] = expm(tM) [x0; 1].  The exit time is the first root
of h(t) = n_e·x(t) - c_e, bracketed on a grid of exact states expm(dt M)^j [x0; 1] (h grows
at least at the guaranteed exit speed inside the triangle, so the root comes before the
exit-time bound) and refined by regula falsi on the Taylor polynomial of the flow from the
bracket's start (exact to rounding over one grid step); the exit point is snapped onto the
exit edge.  Each exit step works relative to its triangle's centre, so precision does not
depend on how far the map lies from the origin.  Samples: every edge crossing plus grid
states near evenly spaced times.  A lasso's cycle is simulated twice; the second lap is the
loop.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NoReturn, cast

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray
from tlmpc.base.content import ContentEquality
from tlmpc.base.errors import SolverError, error
from tlmpc.control.geometry import coordinate_rounding, largest_of, triangle_geometry
from tlmpc.control.model import Controllers, StepController
from tlmpc.mission.model import Mission
from tlmpc.simulate.cells import cell_step
from tlmpc.simulate.matrix import augmented, column_norm, expm_small, taylor_degree

#: Samples per step (besides the crossings): grid points near SAMPLES_PER_STEP - 1 evenly
#: spaced times.
SAMPLES_PER_STEP = 8
#: Grid points that bracket the exit time before root finding, taken this many at a time.
GRID_POINTS = 128
GRID_CHUNK = 16
#: Largest |sM| over which the exit is sought with a Taylor polynomial in s (else expm).
SERIES_RADIUS = 2.0
#: How far (relative to the triangle's size) a state may lie beyond a facet it must not cross
#: before the simulation reports a wrong exit: rounding, not dynamics, at this scale.
WRONG_FACET_TOLERANCE = 1e-9
#: A stay is simulated until the distance to its target shrinks by this factor.
STAY_CONTRACTION = 1e-6


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Trace(ContentEquality):
    """Samples ``(t, x, y)``, the plan step and triangle of each, and the loop's start."""

    times: FloatArray
    points: FloatArray  # (n, 2)
    steps: tuple[int, ...]
    triangles: tuple[int, ...]
    loop_start: int | None
    crossings: tuple[int, ...] = ()


#: 0, 1, ..., m for each Taylor degree m of the local flow (read only).
_EXPONENTS = tuple(np.arange(degree + 1) for degree in range(41))
for _exponents in _EXPONENTS:
    _exponents.setflags(write=False)


def bracketed_root(
    function: Callable[[float], float], low: float, high: float, tolerance: float = 1e-14
) -> float:
    """A root of ``function`` in [low, high], where function(low) < 0 <= function(high).

    Regula falsi with the Illinois modification (superlinear on simple roots, never leaves
    the bracket), and a bisection step when one end has stayed put three times running.  Our
    own 30 lines instead of scipy's brentq: importing scipy.optimize took 0.2 s of every
    compile (the tests compare the two).
    """
    f_low, f_high = function(low), function(high)
    if f_high == 0.0:
        return high
    side = 0
    for _ in range(200):
        if high - low <= tolerance * (1.0 + abs(high)):
            break
        middle = high - f_high * (high - low) / (f_high - f_low)
        if not low < middle < high or side in (-3, 3):
            middle, side = 0.5 * (low + high), 0
        value = function(middle)
        if value == 0.0:
            return middle
        if value < 0.0:
            low, f_low = middle, value
            side = side - 1 if side <= 0 else -1
            if side <= -2:
                f_high *= 0.5  # Illinois: the high end has not moved; shrink its weight
        else:
            high, f_high = middle, value
            side = side + 1 if side >= 0 else 1
            if side >= 2:
                f_low *= 0.5
    return high


def _local_flow(
    matrix: FloatArray,
    base: FloatArray,
    reach: float,
    normal: FloatArray,
    offset: float,
    norm: float | None = None,
) -> tuple[Callable[[float], FloatArray], Callable[[float], float]]:
    """s -> x(s) = expm(sM) base and s -> normal·x(s) - offset for 0 <= s <= reach.

    Over a short reach the Taylor series of expm(sM) base is a polynomial in s with vector
    coefficients M^k base / k!, so the exit height is a scalar polynomial: a root search costs
    a few Horner steps per evaluation instead of a matrix exponential.  ``norm`` is the
    matrix's column norm when known.
    """
    radius = (column_norm(matrix) if norm is None else norm) * reach
    if radius > SERIES_RADIUS:

        def far_point(s: float) -> FloatArray:
            return np.asarray(expm_small(s * matrix).dot(base), dtype=np.float64)

        def far_height(s: float) -> float:
            return float(normal @ far_point(s)[:2] - offset)

        return far_point, far_height
    degree = taylor_degree(radius, 40)
    terms = [base]
    for k in range(1, degree + 1):
        terms.append(matrix.dot(terms[-1]) / k)
    coefficients_of_x = np.array(terms)  # (degree + 1, 3)
    heights = coefficients_of_x[:, :2].dot(normal).tolist()
    heights[0] -= offset
    reversed_heights = heights[::-1]
    exponents = _EXPONENTS[degree]

    def point(s: float) -> FloatArray:
        return np.asarray((s**exponents).dot(coefficients_of_x), dtype=np.float64)

    def height(s: float) -> float:
        value = 0.0
        for coefficient in reversed_heights:
            value = value * s + coefficient
        return value

    return point, height


@dataclass(frozen=True, slots=True)
class _ExitFrame:
    """What an exit step's flow needs of its controller whatever the state it starts from,
    computed once per controller (a lasso's cycle is simulated twice): the same numbers, by
    the same operations, as computing them at every step."""

    normal: FloatArray  # the exit facet's outward normal
    edge_offset: float  # n·x on the exit facet (map coordinates)
    corners: list[list[float]]
    tallest: float
    rounding: float  # of a distance to a facet measured from the corners' coordinates
    center: FloatArray
    matrix: FloatArray  # the augmented matrix of the field relative to ``center``
    matrix_norm: float  # its column norm
    offset: float  # n·y on the exit facet (relative to ``center``)
    others: list[int]  # the two facets it must not cross
    other_normals: FloatArray
    other_offsets: FloatArray
    slack: float


def _exit_frame(controller: StepController) -> _ExitFrame:
    assert controller.exit_edge is not None
    geometry = triangle_geometry(controller.vertices)
    normal = geometry.normals[controller.exit_edge]
    # Per-step bookkeeping on Python floats (numpy's operations in numpy's order: the mean
    # sums the rows first to last): an exit step is a few dozen tiny array operations, and
    # their per-call cost was most of the stage.
    corners = geometry.vertices.tolist()
    tallest = largest_of(geometry.heights.tolist())
    # Coordinates relative to the triangle: y = x - center obeys y' = K y + v(center), whose
    # augmented matrix has the size of the field, not of the map's coordinates (far from the
    # origin the global offset g would dominate it and scaling and squaring would lose digits).
    (x1, y1), (x2, y2), (x3, y3) = corners
    center = np.array([(x1 + x2 + x3) / 3, (y1 + y2 + y3) / 3])
    matrix = augmented(controller.gain, controller.gain @ center + controller.offset)
    # The other two facets, watched too: a field that leaves by an unplanned facet is a bug the
    # simulation must report, not hide by snapping the crossing onto the planned edge.
    others = [j for j in range(3) if j != controller.exit_edge]
    other_normals = geometry.normals[others]
    rounding = coordinate_rounding(geometry.vertices)
    return _ExitFrame(
        normal=normal,
        edge_offset=geometry.offsets[controller.exit_edge],
        corners=corners,
        tallest=tallest,
        rounding=rounding,
        center=center,
        matrix=matrix,
        matrix_norm=column_norm(matrix),
        offset=float(geometry.offsets[controller.exit_edge] - normal @ center),
        others=others,
        other_normals=other_normals,
        other_offsets=geometry.offsets[others] - other_normals @ center,
        # a state is beyond a facet only past the coordinates' rounding: an entry snapped
        # onto the shared edge lies off it by that much, also where the edge meets a kept facet
        slack=WRONG_FACET_TOLERANCE * tallest + rounding,
    )


def _exit_step(
    controller: StepController, x0: FloatArray, frame: _ExitFrame | None = None
) -> tuple[list[float], list[FloatArray]]:
    """Times and points of one exit step, ending with the crossing (snapped to the edge);
    ``frame`` is the controller's :func:`_exit_frame` when already computed."""
    assert controller.exit_edge is not None
    if frame is None:
        frame = _exit_frame(controller)
    normal, corners, center, matrix = frame.normal, frame.corners, frame.center, frame.matrix
    if frame.edge_offset - normal.dot(x0) <= frame.rounding:
        # already on the exit edge to the rounding of the coordinates (a few ulps of the
        # largest; not a fraction of it, which far from the origin is a sizeable part of a
        # small triangle): the crossing is now
        return [0.0], [x0]
    offset = frame.offset
    y0 = x0 - center
    # (numpy's scalar: its division semantics, as computed per step before the frames)
    gap = cast(float, offset - normal.dot(y0))
    horizon = gap / controller.exit_speed
    # h(t) < 0 until the crossing and grows at least at the exit speed inside the triangle, so
    # the first grid point with h >= 0 brackets the crossing (one matrix exponential for the
    # grid step, then matrix-vector products).
    dt = float(horizon * 1.02 / GRID_POINTS)  # (a Python float: the same double, cheaper sums)
    step = expm_small(dt * matrix)
    # The products of one matrix or vector are ``dot``s: the same BLAS calls as ``@`` on 2-D
    # and 1-D arrays (the same bits) at half of matmul's per-call cost; the chunks' stacked
    # products stay matmuls (``dot`` would make them one product of another shape).
    stack = np.empty((GRID_CHUNK, 3, 3))  # step^1 .. step^GRID_CHUNK: a chunk of grid points
    stack[0] = step
    for power in range(1, GRID_CHUNK):
        np.dot(step, stack[power - 1], out=stack[power])
    start = np.array([y0[0], y0[1], 1.0])
    state = start
    others = frame.others
    # All grid states, chunk after chunk from the last state of the one before, then one check
    # of them all (states past the crossing are computed and not used).
    grid_states = np.empty((GRID_POINTS, 3))
    for first in range(0, GRID_POINTS, GRID_CHUNK):
        chunk = grid_states[first : first + GRID_CHUNK]
        np.matmul(stack, state, out=chunk)
        state = chunk[-1]
    # The first grid state on or past the exit edge, and the first beyond another facet
    # (argmax of a boolean array: its first True, or 0 when there is none).
    plane = grid_states[:, :2]
    reached = plane.dot(normal) - offset >= 0.0
    k = int(reached.argmax())
    heights = plane.dot(frame.other_normals.T) - frame.other_offsets
    beyond = np.maximum(heights[:, 0], heights[:, 1]) > frame.slack
    first_outside = int(beyond.argmax())
    if beyond[first_outside] and (not reached[k] or first_outside < k):
        _wrong_exit(controller, others, grid_states[first_outside, :2] + center)
    if not reached[k]:
        raise SolverError(
            error(
                "C010",
                f"plan step {controller.step}: the trajectory did not "
                "leave its triangle within the exit-time bound",
                hint="please report this mission",
            )
        )
    lower, before = k * dt, start if k == 0 else grid_states[k - 1]
    point, height = _local_flow(matrix, before, dt, normal, offset, frame.matrix_norm)
    if height(0.0) >= 0.0:
        within = 0.0  # rounding put the bracket's start on the edge already
    elif height(dt) < 0.0:
        within = dt  # the grid's iterates and the local series differ by rounding
    else:
        # Sought in units of the grid step: the root finder's tolerance is relative to its
        # bracket, so a step of 1e-13 s (a fast robot on a tiny map) is as exact as one of 1 s.
        within = dt * bracketed_root(lambda u: height(dt * u), 0.0, 1.0)
    crossing = lower + within
    end = point(within)[:2] + center
    # Samples: the grid points nearest to evenly spaced times (exact states, no extra work).
    grid = grid_states[:k]  # grid states before the crossing
    indices = _sample_indices(float(crossing), float(dt), k)
    times = [float(j * dt) for j in indices]
    points = list(grid[[j - 1 for j in indices], :2] + center)
    # Snap onto the exit edge (the root is exact to ~1e-14; this removes the residue).
    # (On Python floats: a dot of two is ax bx + ay by, as numpy computes it.)
    ax, ay = corners[(controller.exit_edge + 1) % 3]
    bx, by = corners[(controller.exit_edge + 2) % 3]
    ex, ey = end.tolist()
    dx, dy = bx - ax, by - ay
    squared = dx * dx + dy * dy
    along = ((ex - ax) * dx + (ey - ay) * dy) / squared if squared > 0.0 else math.nan
    if not -WRONG_FACET_TOLERANCE <= along <= 1.0 + WRONG_FACET_TOLERANCE:
        _wrong_exit(controller, others, end)
    along = min(max(along, 0.0), 1.0)
    return [*times, float(crossing)], [*points, np.array([ax + along * dx, ay + along * dy])]


def _sample_indices(crossing: float, dt: float, count: int) -> list[int]:
    """The grid points (1 .. ``count``) nearest to the times j * crossing / SAMPLES_PER_STEP,
    j = 1 .. SAMPLES_PER_STEP - 1, each once, in order: (j * (crossing / SAMPLES_PER_STEP)) / dt
    rounded half to even, as numpy's ``rint`` rounds (Python's ``round`` on the same floats
    rounds alike, without numpy's per-call cost)."""
    share = crossing / SAMPLES_PER_STEP
    wanted = {round(j * share / dt) for j in range(1, SAMPLES_PER_STEP)}
    return sorted(j for j in wanted if 1 <= j <= count)


def exit_step(controller: StepController, x0: FloatArray) -> tuple[list[float], list[FloatArray]]:
    """Times (from 0) and exact points of the flow of an exit step's field from ``x0`` until it
    crosses the exit edge; the last pair is the crossing, snapped onto the edge."""
    return _exit_step(controller, x0)


def _wrong_exit(controller: StepController, facets: list[int], where: FloatArray) -> NoReturn:
    raise SolverError(
        error(
            "C031",
            f"plan step {controller.step}: the field leaves triangle {controller.triangle} "
            f"across facet {' or '.join(map(str, facets))} near ({where[0]:.6g}, {where[1]:.6g}), "
            f"not through the planned exit facet {controller.exit_edge}",
            hint="please report this mission; the controllers do not realise the plan",
        )
    )


def _stay_step(
    controller: StepController, x0: FloatArray, max_speed: float
) -> tuple[list[float], list[FloatArray]]:
    """Convergence to the target: samples on a geometric time grid, then the limit point."""
    assert controller.target is not None
    target = np.asarray(controller.target)
    rate = -float(np.max(np.linalg.eigvals(controller.gain).real))
    if rate <= 0:
        raise SolverError(
            error(
                "C011",
                f"plan step {controller.step}: the stay field does not converge",
                hint="please report this mission",
            )
        )
    horizon = math.log(1.0 / STAY_CONTRACTION) / rate
    times = [
        float(t) for t in horizon * (np.geomspace(1.0, 1001.0, 4 * SAMPLES_PER_STEP) - 1.0) / 1000.0
    ][1:]
    points = [target + expm_small(t * controller.gain) @ (x0 - target) for t in times]
    # The limit point itself, reached "at infinity": placed after the last sample at a time
    # that keeps the stated speed bound.
    last = points[-1]
    times.append(times[-1] + max(float(np.linalg.norm(last - target)) / max_speed, 1e-9) + 1e-9)
    points.append(target)
    return times, points


def pursuit_step(
    controller: StepController, x0: FloatArray, max_speed: float
) -> tuple[list[float], list[FloatArray]]:
    """A vertex passage, exactly: the pursuit law moves straight to the corner at
    ``max_speed``, arriving after |v - x0| / max_speed; the last sample is the corner itself
    (exactly its coordinates, so the verifier reads the point's label there)."""
    assert controller.target is not None
    target = np.asarray(controller.target, dtype=np.float64)
    distance = float(np.linalg.norm(target - x0))
    return [distance / max_speed], [target]


def simulate(
    abstraction: Abstraction,
    controllers: Controllers,
    mission: Mission,
    *,
    max_gap: float | None = None,
) -> Trace:
    """The trajectory from ``mission.robot.start`` under ``controllers``.

    With ``max_gap`` no two samples of a step's field or vertex passage are further apart in
    time (the samples between are the same flow, exactly: :func:`_fill`); the samples
    without it are all still there, bit for bit.  A cell step keeps its own samples."""
    del abstraction  # the controllers carry their triangles' geometry
    steps = list(controllers.steps)
    order = list(range(len(steps)))
    loop_start_step = controllers.loop_start
    if loop_start_step is not None:
        cycle = order[loop_start_step:]
        order = [*order, *cycle]  # the cycle twice
    x = np.asarray(mission.robot.start, dtype=np.float64)
    times: list[float] = [0.0]
    points: list[FloatArray] = [x]
    step_of: list[int] = [order[0]]
    triangle_of: list[int] = [steps[order[0]].triangle]
    crossings: list[int] = []
    loop_index: int | None = None
    frames: dict[int, _ExitFrame] = {}  # per plan step: the cycle's second lap reuses them
    now = 0.0
    for position, index in enumerate(order):
        controller = steps[index]
        if loop_start_step is not None and index == loop_start_step and position == len(steps):
            loop_index = len(points) - 1  # the crossing into the second lap
        if controller.is_cell:
            cell_times, cell_points, cell_triangles, cell_crossings = cell_step(
                controller, x, controllers.max_speed
            )
            for t, point, triangle, crossed in zip(
                cell_times, cell_points, cell_triangles, cell_crossings, strict=True
            ):
                if t <= 0.0:
                    continue
                times.append(now + t)
                points.append(point)
                step_of.append(index)
                triangle_of.append(triangle)
                if crossed:
                    crossings.append(len(points) - 1)
            now = times[-1]
            x = points[-1]
            continue
        if controller.is_vertex:
            rel_times, rel_points = pursuit_step(controller, x, controllers.max_speed)
        elif controller.exit_edge is None:
            rel_times, rel_points = _stay_step(controller, x, controllers.max_speed)
        else:
            frame = frames.get(index)
            if frame is None:
                frame = frames[index] = _exit_frame(controller)
            rel_times, rel_points = _exit_step(controller, x, frame)
        # Per step, not per sample: the last sample is the crossing (but for a stay), in the
        # next triangle where there is one.
        last = -1 if controller.is_stay else len(rel_times) - 1
        inside = controller.triangle
        beyond = inside if controller.next_triangle is None else controller.next_triangle
        # Samples at time 0 or before (the start already on the exit edge) are not taken: the
        # current sample is then the crossing.  The sample times rise, so they lead.
        taken = 0
        while taken < len(rel_times) and rel_times[taken] <= 0.0:
            if controller.next_triangle is not None:
                triangle_of[-1] = controller.next_triangle
            crossings.append(len(points) - 1)
            taken += 1
        rest_times, rest_points = rel_times[taken:], rel_points[taken:]
        if max_gap is not None and rest_times:
            rest_times, rest_points = _fill(
                controller, x, rest_times, rest_points, max_gap, controllers.max_speed
            )
        count = len(rest_times)
        if count:  # the step's other samples, its lists extended at once
            times.extend([now + t for t in rest_times])
            points.extend(rest_points)
            step_of.extend([index] * count)
            if last < 0:
                triangle_of.extend([inside] * count)
            else:
                triangle_of.extend([inside] * (count - 1))
                triangle_of.append(beyond)
                crossings.append(len(points) - 1)
        now = times[-1]
        x = points[-1]
    if loop_start_step is not None and loop_index is None:  # pragma: no cover - defensive
        raise SolverError(error("C012", "could not mark the loop of the trajectory"))
    return Trace(
        times=np.asarray(times),
        points=np.asarray(points),
        steps=tuple(step_of),
        triangles=tuple(triangle_of),
        loop_start=loop_index,
        crossings=tuple(crossings),
    )


def _fill(
    controller: StepController,
    x0: FloatArray,
    rel_times: list[float],
    rel_points: list[FloatArray],
    max_gap: float,
    max_speed: float,
) -> tuple[list[float], list[FloatArray]]:
    """The step's samples with more in every gap longer than ``max_gap`` (from the step's
    start ``x0`` at time 0): a vertex passage's straight line at ``max_speed``, a field's
    flow x' = K x + g from the sample before, exp(t [[K, g], [0, 0]]) on (x, 1)."""
    filled_times: list[float] = []
    filled_points: list[FloatArray] = []
    flow = np.zeros((3, 3))
    flow[:2, :2] = controller.gain
    flow[:2, 2] = controller.offset
    before_time, before_point = 0.0, np.asarray(x0, dtype=np.float64)
    for time, point in zip(rel_times, rel_points, strict=True):
        gap = time - before_time
        pieces = math.ceil(gap / max_gap) if gap > max_gap else 1
        towards = np.asarray(point, dtype=np.float64) - before_point
        for k in range(1, pieces):
            dt = gap * k / pieces
            if controller.is_vertex:
                along = dt * max_speed / float(np.linalg.norm(towards))
                filled_points.append(before_point + along * towards)
            else:
                state = expm_small(dt * flow).dot(np.array([*before_point, 1.0]))
                filled_points.append(state[:2])
            filled_times.append(before_time + dt)
        filled_times.append(time)
        filled_points.append(point)
        before_time, before_point = time, np.asarray(point, dtype=np.float64)
    return filled_times, filled_points


def trace_header(mission: Mission, max_speed: float) -> dict[str, Any]:
    """What ``trace.json`` takes from the mission (all but the samples), so that a trace
    verifies on its own: task, regions, every workspace piece, convention, speed, body."""
    from tlmpc.ltl.printer import to_text
    from tlmpc.mission.body import body_radius
    from tlmpc.mission.model import regions_document

    return {
        "format": "tlmpc.trace/1",
        "ltl": to_text(mission.formula),
        "regions": regions_document([(r.name, r.polygon) for r in mission.regions]),
        "workspace": mission.workspace.to_json(),
        "boundary": mission.options.boundary,
        "max_speed": max_speed,
        **({"radius": radius} if (radius := body_radius(mission.robot)) > 0.0 else {}),
    }


def trace_to_json(trace: Trace, mission: Mission) -> dict[str, object]:
    """``trace.json`` (``tlmpc.trace/1``): self-contained, so it verifies on its own."""
    return {
        **trace_header(mission, mission.robot.max_speed),
        "points": np.column_stack([trace.times, trace.points]).tolist(),
        "loop_start": trace.loop_start,
        # A plan's run is infinite: the trace either loops or ends in a stay.
        "end": "stay" if trace.loop_start is None else "loop",
        "steps": list(trace.steps),
        "triangles": list(trace.triangles),
        "crossings": list(trace.crossings),
    }
