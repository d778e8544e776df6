"""Stage 6: affine feedback fields per plan step (Belta–Isler–Pappas vertex programs).

Every plan step is a triangle and the edge to leave it by.  The vertex velocities w_i of a
step must (1) keep the two other facets invariant with a margin, n_j·w_i <= -margin * s,
(2) push across the exit facet, n_e·w_i >= s for all three vertices (then every state of the
closed triangle leaves through the exit edge in finite time), and (3) respect the speed
bound exactly, |w_i| <= max_speed (second-order cones).  The field inside the triangle is
the affine interpolation of the w_i, so the bound holds everywhere.

Continuity: a vertex shared by consecutive steps keeps one velocity for as long as the
constraints it collects stay compatible (their normals fit in an open half-plane: a fan of
less than 180°); otherwise the velocity jumps there, which is reported.  All steps are one
second-order-cone program, handed to Clarabel directly in its conic form (importing cvxpy
alone took 0.5 s, most of what compiling Example 8 takes; the tests solve the same program
with cvxpy and compare the optima).
"""

from __future__ import annotations

import math
import time
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray
from tlmpc.base.errors import InvalidInputError, SolverError, error
from tlmpc.control.channel import label_clearance
from tlmpc.control.follow import bends, follow_channel, path_guides
from tlmpc.control.geometry import (
    TriangleGeometry,
    affine_law,
    affine_laws,
    best_push,
    half_plane_feasible,
    largest_of,
    triangle_geometry,
)
from tlmpc.control.model import Controllers, StepController, VelocityJump
from tlmpc.control.robust import (
    Corner,
    best_push_velocities,
    corner_angle,
    disturbance_hint,
    weakest,
)
from tlmpc.control.sparse import CscMatrix, Triplets, stacked_csc
from tlmpc.mission.model import Robot
from tlmpc.planning.mission import SUPPORTED, SUPPORTED_CELLS, on_cells
from tlmpc.planning.model import Witness
from tlmpc.planning.robust import best_direction

#: A unit normal as Python floats.
Vector = tuple[float, float]

#: Invariance margin: non-exit facets are pushed inward at least MARGIN times the exit speed.
MARGIN = 0.3


@dataclass(slots=True)
class _Step:
    triangle: int
    exit_edge: int | None
    next_triangle: int | None
    geometry: TriangleGeometry
    runs: list[int] = field(default_factory=list)  # run id per local vertex
    through: int | None = None  # a vertex passage: the mesh vertex pursued (no program)
    rows: list[list[tuple[Vector, float]]] | None = None  # _normals per local vertex, once


def plan_steps(abstraction: Abstraction, witness: Witness) -> tuple[list[_Step], int | None]:
    """The (triangle, exit edge) steps of the lasso, and the first step of a moving cycle.

    A vertex passage is a step of its own (``through`` set, no exit edge); the step after it
    starts at that vertex and must leave through the edge opposite it (or stay).
    """
    path = [*witness.prefix, *witness.cycle]
    stay = witness.is_stay
    passages = dict(witness.passages)
    neighbors = abstraction.neighbors
    steps: list[_Step] = []
    for index, tri in enumerate(path):
        if stay and index == len(path) - 1:
            nxt = None
        elif index + 1 < len(path):
            nxt = path[index + 1]
        else:
            nxt = witness.cycle[0]
        geometry = triangle_geometry(abstraction.corners(tri))
        if index in passages and nxt is not None:
            vertex = passages[index]
            if vertex not in abstraction.triangles[tri] or vertex not in abstraction.triangles[nxt]:
                raise InvalidInputError(
                    error(
                        "C040",
                        f"plan step {index}: the passage vertex {vertex} is not a corner of "
                        f"both triangles {tri} and {nxt}",
                        hint="the witness does not belong to this abstraction",
                    )
                )
            steps.append(_Step(tri, None, nxt, geometry, through=vertex))
            continue
        exit_edge = None
        if nxt is not None:
            matches = [edge for edge, other in enumerate(neighbors[tri].tolist()) if other == nxt]
            if len(matches) != 1:
                raise InvalidInputError(
                    error(
                        "C001",
                        f"plan step {index}: triangles {tri} and {nxt} are not adjacent",
                        hint="the witness does not belong to this abstraction",
                    )
                )
            exit_edge = int(matches[0])
            entries = {path[index - 1]} if index > 0 else set()
            if not stay and index == len(witness.prefix):
                entries.add(witness.cycle[-1])  # later laps enter from the cycle's end
            if nxt in entries:
                raise InvalidInputError(
                    error(
                        "C002",
                        f"plan step {index} bounces: it enters triangle {tri} from "
                        f"{nxt} and leaves back to {nxt}",
                        hint="an affine field cannot leave a triangle through its entry edge",
                    )
                )
            arrivals = [passages.get(index - 1)] if index > 0 else []
            if not stay and index == len(witness.prefix):
                arrivals.append(passages.get(len(path) - 1))  # later laps
            for arrived in arrivals:
                if arrived is None:
                    continue
                corners = abstraction.triangles[tri].tolist()
                if arrived not in corners or exit_edge != corners.index(arrived):
                    raise InvalidInputError(
                        error(
                            "C040",
                            f"plan step {index} starts at vertex {arrived} of triangle {tri} "
                            "and does not leave through the edge opposite it",
                            hint="after a vertex passage only the edge opposite the vertex "
                            "can be left; the witness does not belong to this abstraction",
                        )
                    )
        steps.append(_Step(tri, exit_edge, nxt, geometry))
    loop_start = None if stay else len(witness.prefix)
    return steps, loop_start


def _normals(step: _Step, local: int) -> list[tuple[Vector, float]]:
    """(a, c) pairs meaning a·w >= c·s for the velocity at local vertex ``local``.

    Computed once per step on Python floats (the runs and the program each ask for every
    vertex; numpy's per-call overhead on 2-vectors dominated).
    """
    if step.rows is None:
        normals = step.geometry.normals.tolist()
        step.rows = []
        for vertex in range(3):
            rows: list[tuple[Vector, float]] = []
            for facet in range(3):
                if facet == vertex:
                    continue  # the vertex is not on the facet opposite it
                if facet == step.exit_edge:
                    continue
                nx, ny = normals[facet]
                rows.append(((-nx, -ny), MARGIN))
            if step.exit_edge is not None:
                nx, ny = normals[step.exit_edge]
                rows.append(((nx, ny), 1.0))
            step.rows.append(rows)
    return step.rows[local]


class _Runs:
    """Union-find over (vertex, run) variables with the constraint normals each collects."""

    def __init__(self, push: float = 0.0, max_speed: float = 1.0) -> None:
        self.parent: list[int] = []
        self.normals: list[list[Vector]] = []
        # With a disturbance, one velocity must push at least ``push`` along every normal it
        # collects, not merely be positive along each.
        self.push, self.max_speed = push, max_speed

    def compatible(self, normals: list[Vector]) -> bool:
        if self.push <= 0.0:
            return half_plane_feasible(normals)
        return best_push(normals, self.max_speed) > self.push

    def new(self, normals: list[Vector]) -> int:
        self.parent.append(len(self.parent))
        self.normals.append(list(normals))
        return len(self.parent) - 1

    def find(self, run: int) -> int:
        while self.parent[run] != run:
            self.parent[run] = self.parent[self.parent[run]]
            run = self.parent[run]
        return run

    def try_extend(self, run: int, normals: list[Vector]) -> bool:
        root = self.find(run)
        if self.compatible(self.normals[root] + normals):
            self.normals[root].extend(normals)
            return True
        return False

    def try_merge(self, first: int, second: int) -> bool:
        a, b = self.find(first), self.find(second)
        if a == b:
            return True
        if not self.compatible(self.normals[a] + self.normals[b]):
            return False
        self.parent[b] = a
        self.normals[a].extend(self.normals[b])
        return True


def _assign_runs(
    abstraction: Abstraction,
    steps: list[_Step],
    loop_start: int | None,
    *,
    push: float = 0.0,
    max_speed: float = 1.0,
    split: Mapping[tuple[int, int], str] | None = None,
) -> tuple[_Runs, list[VelocityJump]]:
    """Velocity runs; ``split`` maps (step, vertex) pairs that start a new run to why (where
    the path to follow bends, or sharing would turn a field away from it:
    :func:`tlmpc.control.follow.bends`)."""
    split = {} if split is None else split
    runs = _Runs(push, max_speed)
    jumps: list[VelocityJump] = []
    previous: dict[int, int] = {}  # global vertex -> run id at the previous step
    for index, step in enumerate(steps):
        if step.through is not None:
            previous = {}  # the pursuit law between: no velocity to share across it
            continue
        vertices = abstraction.triangles[step.triangle].tolist()
        current: dict[int, int] = {}
        for local, vertex in enumerate(vertices):
            normals = [a for a, _ in _normals(step, local)]
            run = previous.get(vertex)
            reason = None
            if run is not None and step.exit_edge is None:
                reason = "the stay field has its own vertex velocities"
            elif run is not None and (index, vertex) in split:
                reason = split[(index, vertex)]
            elif run is not None and not runs.try_extend(run, normals):
                reason = "the path turns 180° or more around this vertex"
            if run is None or reason is not None:
                if reason is not None:
                    x, y = abstraction.vertices[vertex].tolist()
                    jumps.append(
                        VelocityJump(step=index, vertex=vertex, position=(x, y), reason=reason)
                    )
                run = runs.new(normals)
            current[vertex] = run
            step.runs.append(run)
        previous = current
    if loop_start is not None and steps[loop_start].through is None:
        first = steps[loop_start]
        first_vertices = abstraction.triangles[first.triangle].tolist()
        for local, vertex in enumerate(first_vertices):
            if vertex not in previous:
                continue
            bent = split.get((loop_start, vertex))
            if bent is not None or not runs.try_merge(previous[vertex], first.runs[local]):
                x, y = abstraction.vertices[vertex].tolist()
                jumps.append(
                    VelocityJump(
                        step=loop_start,
                        vertex=vertex,
                        position=(x, y),
                        reason=bent or "the cycle turns 180° or more around this vertex",
                    )
                )
    for step in steps:
        step.runs = [runs.find(r) for r in step.runs]
    return runs, jumps


@dataclass(frozen=True, slots=True)
class VertexProgram:
    """The controller program over z = (w_1, ..., w_R, s_1, ..., s_N) and a floor f:

    maximise f + 0.1 * mean(s) subject to ``inequality @ z >= 0``, ``equality @ z == 0`` (stay
    targets), |w_r| <= max_speed, and s_k >= f.
    """

    inequality: Triplets
    equality: Triplets | None
    runs: int
    steps: int
    max_speed: float
    disturbance: float = 0.0  # every inequality row must hold with this much to spare

    def objective(self, z: FloatArray, floor: float) -> float:
        """The maximised value at a candidate solution."""
        return float(floor + 0.1 * z[2 * self.runs :].sum() / self.steps)


def vertex_program(
    steps: list[_Step], max_speed: float, disturbance: float = 0.0
) -> tuple[VertexProgram, dict[int, int]]:
    """The program of ``steps`` and the column of each run's root."""
    roots = sorted({r for step in steps for r in step.runs})
    column = {r: i for i, r in enumerate(roots)}
    count, n_steps = len(roots), len(steps)
    rows, cols, vals = [], [], []
    eq_rows, eq_cols, eq_vals = [], [], []
    row = eq_row = 0
    for k, step in enumerate(steps):
        for local, run in enumerate(step.runs):
            base = 2 * column[run]
            for normal, coefficient in _normals(step, local):
                rows += [row, row, row]
                cols += [base, base + 1, 2 * count + k]
                vals += [normal[0], normal[1], -coefficient]
                row += 1
        if step.exit_edge is None:
            weights = step.geometry.barycentric(step.geometry.incenter())
            for dim in range(2):
                for local, run in enumerate(step.runs):
                    eq_rows.append(eq_row)
                    eq_cols.append(2 * column[run] + dim)
                    eq_vals.append(weights[local])
                eq_row += 1
    size = 2 * count + n_steps
    inequality = Triplets.build(rows, cols, vals, (row, size))
    equality = Triplets.build(eq_rows, eq_cols, eq_vals, (eq_row, size)) if eq_row else None
    program = VertexProgram(inequality, equality, count, n_steps, max_speed, disturbance)
    return program, column


@dataclass(frozen=True, slots=True)
class ConicForm:
    """Clarabel's form of a vertex program: min costs·x subject to
    constraints @ x + s = offsets, s in the cones (kind, dimension) in row order."""

    constraints: CscMatrix
    costs: FloatArray
    offsets: FloatArray
    cones: tuple[tuple[str, int], ...]


def conic_form(program: VertexProgram) -> ConicForm:
    """The program in Clarabel's form; x = (z, f).

    The cones are: zero (stay targets), non-negative (the facet rows and s_k - f), and one
    three-dimensional second-order cone (max_speed, w_r) per run.
    """
    count, n_steps = program.runs, program.steps
    size = 2 * count + n_steps
    blocks: list[tuple[int, Triplets]] = []
    offsets: list[FloatArray] = []
    cones: list[tuple[str, int]] = []
    row = 0
    if program.equality is not None:
        blocks.append((row, program.equality))
        row += program.equality.shape[0]
        offsets.append(np.zeros(program.equality.shape[0]))
        cones.append(("zero", program.equality.shape[0]))
    inequality = program.inequality
    negated = Triplets(inequality.rows, inequality.cols, -inequality.values, inequality.shape)
    blocks.append((row, negated))
    inequality_rows = inequality.shape[0]
    row += inequality_rows
    # s_k - f >= 0: -1 at s_k, +1 at f (column size).
    steps = np.arange(n_steps, dtype=np.int64)
    speeds = Triplets.build(
        np.repeat(steps, 2),
        np.stack([2 * count + steps, np.full(n_steps, size)], axis=1),
        np.tile([-1.0, 1.0], n_steps),
        (n_steps, size + 1),
    )
    blocks.append((row, speeds))
    row += n_steps
    # Robust rows: a·w >= c·s + disturbance, i.e. a·(w + δ) >= c·s for every |δ| <= it.
    spare = program.disturbance / program.max_speed
    offsets.append(np.concatenate([np.full(inequality_rows, -spare), np.zeros(n_steps)]))
    cones.append(("nonnegative", inequality_rows + n_steps))
    # (max_speed, w_r) in the cone: rows (0; -e_2r; -e_2r+1), offsets (max_speed; 0; 0).
    soc_rows = np.arange(3 * count, dtype=np.int64).reshape(count, 3)[:, 1:].ravel()
    blocks.append(
        (
            row,
            Triplets.build(
                soc_rows, np.arange(2 * count), -np.ones(2 * count), (3 * count, size + 1)
            ),
        )
    )
    row += 3 * count
    cone_offsets = np.zeros(3 * count)
    # Solved at unit speed and scaled back below: the solver's absolute tolerances (1e-8) are
    # then relative to max_speed, whatever its magnitude (at 1e-9 m/s they would swamp it).
    # Triangle sizes never enter: the rows hold unit normals and barycentric weights.
    # With a disturbance the rows are not homogeneous and the shrink below would break them:
    # solve inside a disc smaller than the solver's tolerance instead.
    cone_offsets[::3] = 1.0 if program.disturbance == 0.0 else 1.0 - 1e-7
    offsets.append(cone_offsets)
    cones += [("second-order", 3)] * count
    costs = np.zeros(size + 1)
    costs[2 * count : size] = -0.1 / n_steps
    costs[size] = -1.0
    return ConicForm(
        constraints=stacked_csc(blocks, (row, size + 1)),
        costs=costs,
        offsets=np.concatenate(offsets),
        cones=tuple(cones),
    )


def solve_vertex_program(program: VertexProgram) -> tuple[FloatArray, FloatArray]:
    """Velocities per run (R, 2) and guaranteed speeds per step (N,), by Clarabel
    (the program in :func:`conic_form`)."""
    import clarabel

    count, n_steps = program.runs, program.steps
    size = 2 * count + n_steps
    form = conic_form(program)
    kinds = {
        "zero": clarabel.ZeroConeT,
        "nonnegative": clarabel.NonnegativeConeT,
        "second-order": clarabel.SecondOrderConeT,
    }
    cones = [kinds[kind](dim) for kind, dim in form.cones]
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    empty = np.zeros(0, dtype=np.int64)
    solver = clarabel.DefaultSolver(
        CscMatrix(np.zeros(0), empty, np.zeros(size + 2, dtype=np.int64), (size + 1, size + 1)),
        form.costs,
        form.constraints,
        form.offsets,
        cones,
        settings,
    )
    solution = solver.solve()
    status = str(solution.status)
    if status not in ("Solved", "AlmostSolved"):
        raise SolverError(
            error(
                "C003",
                f"the controller program ended {status!r}",
                hint="please report this mission",
            )
        )
    values = np.asarray(solution.x, dtype=np.float64) * program.max_speed
    velocities, speeds = values[: 2 * count].reshape(count, 2), values[2 * count : size]
    # The solver meets |w| <= 1 only to its tolerance.  Every other constraint is homogeneous,
    # so one common scale makes the speed bound exact and keeps them all.
    largest = float(np.linalg.norm(velocities, axis=1).max()) if count else 0.0
    if largest > program.max_speed and program.disturbance == 0.0:
        shrink = program.max_speed / largest * (1.0 - 4 * np.finfo(np.float64).eps)
        velocities, speeds = velocities * shrink, speeds * shrink
    return velocities, speeds


#: The re-check after solving demands each guarantee with this much to spare, relative to
#: max_speed: a condition met only to the solver's tolerance is not met.
RECHECK_TOLERANCE = 1e-9


def run_push(robot: Robot) -> float:
    """How hard a velocity shared along a vertex run must push along every facet the run
    collects: harder than the disturbance (as the re-check demands), or, without one, merely
    positively (0)."""
    if robot.disturbance > 0.0:
        return robot.disturbance * (1.0 + RECHECK_TOLERANCE) + RECHECK_TOLERANCE * robot.max_speed
    return 0.0


def violated_condition(
    controller: StepController,
    max_speed: float,
    disturbance: float = 0.0,
    geometry: TriangleGeometry | None = None,
) -> str | None:
    """Which vertex condition the solved field breaks (None when all hold), re-derived from the
    triangle: speed bound, exit across the planned facet, invariance of the two others; for a
    stay, inward on every facet, equilibrium at its target and a Hurwitz gain.  ``geometry``
    is the triangle's when already computed from the very array ``controller.vertices``."""
    if geometry is None or geometry.vertices is not controller.vertices:
        geometry = triangle_geometry(controller.vertices)
    # Python floats, numpy's operations in numpy's order (|w| = sqrt(wx wx + wy wy), a dot
    # of two is ax bx + ay by): the array code's values, without its per-call cost.
    w = controller.velocities.tolist()
    normals = geometry.normals.tolist()
    floor = disturbance + RECHECK_TOLERANCE * max_speed
    fastest = largest_of([math.sqrt(wx * wx + wy * wy) for wx, wy in w])
    if fastest > max_speed * (1.0 + RECHECK_TOLERANCE):
        return f"a vertex speed {fastest:.6g} exceeds max_speed {max_speed:.6g}"
    for i in range(3):
        wx, wy = w[i]
        for facet in range(3):
            if facet == i:
                continue
            nx, ny = normals[facet]
            across = nx * wx + ny * wy
            if facet == controller.exit_edge and across <= floor:
                return f"vertex {i} does not move across the exit facet (speed {across:.3g})"
            if facet != controller.exit_edge and -across <= floor:
                return f"vertex {i} is not pushed inside facet {facet} (inward {-across:.3g})"
    if controller.exit_edge is not None:
        (nx, ny), (wx, wy) = normals[controller.exit_edge], w[controller.exit_edge]
        if nx * wx + ny * wy <= floor:
            return "the vertex opposite the exit does not move toward it"
        return None
    assert controller.target is not None
    target = np.asarray(controller.target)
    # Far from the origin K x and g are large and cancel: allow their rounding, no more.
    rounding = (
        8
        * float(np.finfo(np.float64).eps)
        * (
            float(np.abs(controller.gain).sum() * np.abs(target).max())
            + float(np.abs(controller.offset).max())
        )
    )
    residual = float(np.linalg.norm(controller.gain @ target + controller.offset))
    if residual > floor + rounding:
        return f"the stay field does not vanish at its target (speed {residual:.3g} there)"
    if float(geometry.barycentric(target).min()) <= 0.0:
        return "the stay target is not inside the triangle"
    if float(np.max(np.linalg.eigvals(controller.gain).real)) >= 0.0:
        return "the stay field's gain is not Hurwitz"
    return None


def _corner(
    abstraction: Abstraction, index: int, step: _Step, local: int, max_speed: float
) -> Corner:
    """Corner ``local`` of ``step`` and its push (what it can reject)."""
    normals = [a for a, _ in _normals(step, local)]
    corners = step.geometry.vertices.tolist()
    x, y = corners[local]
    return Corner(
        step=index,
        triangle=step.triangle,
        position=(x, y),
        angle=corner_angle(corners, local),
        # (best_direction keeps a sliver corner's digits; best_push drops its bisector)
        push=best_direction(normals)[0] * max_speed,
        kept=step.exit_edge is None or step.exit_edge == local,
    )


def _check_rejectable(
    abstraction: Abstraction,
    steps: list[_Step],
    robot: Robot,
    source: str | None,
    supported: float | None = None,
    on_cells: float | None = None,
) -> None:
    """Located errors where no vertex velocity can reject ``robot.disturbance`` (C032/C033),
    and where the plan passes through a single point, which no law here reaches under a
    disturbance (C034)."""
    if robot.disturbance >= robot.max_speed:
        raise InvalidInputError(
            error(
                "C033",
                f"robot.disturbance {robot.disturbance:g} is not below max_speed "
                f"{robot.max_speed:g}: no controller can reject it",
                hint="the disturbance bound must be smaller than max_speed",
                file=source,
                path="$.robot.disturbance",
            )
        )
    problems = []
    pushes: list[Corner] = []
    for index, step in enumerate(steps):
        if step.through is not None:
            # The pursuit law closes in on the corner at s - d, but a push across the pursuit
            # direction turns the robot about the corner at d / r, unboundedly fast as r -> 0:
            # it leaves the triangle beside the corner before it arrives.
            x, y = abstraction.vertices[step.through].tolist()
            problems.append(
                error(
                    "C034",
                    f"plan step {index} (triangle {step.triangle}) passes through the single "
                    f"point ({x:.6g}, {y:.6g}), which no controller here reaches under a "
                    f"disturbance: a push of {robot.disturbance:g} across the way to the "
                    "point turns the robot about it faster the nearer it gets, so it leaves "
                    "the triangle beside the point",
                    hint="the task is met only through this point (regions touching at a "
                    "corner, or a pinch): set robot.disturbance to 0, or let the regions share "
                    "an edge",
                    file=source,
                    path="$.robot.disturbance",
                )
            )
            continue
        corners = abstraction.triangles[step.triangle].tolist()
        for local in range(3):
            corner = _corner(abstraction, index, step, local, robot.max_speed)
            pushes.append(corner)
            if corner.push <= robot.disturbance * (1.0 + RECHECK_TOLERANCE):
                x, y = abstraction.vertices[corners[local]].tolist()
                problems.append(
                    error(
                        "C032",
                        f"plan step {index} (triangle {step.triangle}): at the corner "
                        f"({x:.6g}, {y:.6g}) a velocity within max_speed pushes at most "
                        f"{corner.push:.4g} along every facet it must, not more than the "
                        f"disturbance {robot.disturbance:g}",
                        file=source,
                        path="$.robot.disturbance",
                    )
                )
    if problems:
        hint = disturbance_hint(
            robot.disturbance,
            robot.max_speed,
            weakest(pushes),
            supported=supported,
            on_cells=on_cells,
            triangles=abstraction.num_triangles,
        )
        raise InvalidInputError([replace(p, hint=hint) for p in problems[:10]])


def pursuit_controller(
    index: int, step: _Step, vertex: FloatArray, max_speed: float, disturbance: float = 0.0
) -> StepController:
    """The vertex passage of ``step``: pursue the corner ``vertex`` at ``max_speed``.

    Every point x of the (convex) triangle moves straight to the corner and arrives after
    |v - x| / max_speed, or |v - x| / (max_speed - disturbance) under a disturbance below
    max_speed (the component along the pursuit direction is at least max_speed - d).
    """
    corners = step.geometry.vertices
    offsets = vertex[None, :] - corners
    distances = np.linalg.norm(offsets, axis=1)
    velocities = np.zeros_like(corners)
    moving = distances > 0.0
    velocities[moving] = max_speed * offsets[moving] / distances[moving, None]
    velocities.setflags(write=False)
    closing = max_speed - disturbance
    return StepController(
        step=index,
        triangle=step.triangle,
        exit_edge=None,
        next_triangle=step.next_triangle,
        vertices=corners,
        velocities=velocities,
        gain=np.zeros((2, 2)),
        offset=np.zeros(2),
        exit_speed=closing,
        exit_time_bound=float(distances.max()) / closing,
        target=(float(vertex[0]), float(vertex[1])),
        kind="vertex",
    )


def synthesize(
    abstraction: Abstraction,
    witness: Witness,
    robot: Robot,
    *,
    source: str | None = None,
    follow: bool = True,
    relevant: Collection[str] | None = None,
) -> Controllers:
    """One affine field per plan step realising ``witness`` under ``robot.max_speed``, robust
    to any additive velocity disturbance up to ``robot.disturbance``.

    ``source`` names the mission file in diagnostics.  With ``follow`` (the default) the
    fields are chosen so that their flow follows the shortest path through the plan's
    channel (:mod:`tlmpc.control.follow`), under the vertex program's constraints, keeping
    the label clearance from the boundaries of the ``relevant`` regions (all when None; a
    compile passes the task's propositions).
    """
    if on_cells(witness):
        # a plan made on convex cells: its steps are cell steps (tlmpc.control.cells)
        from tlmpc.control.cells import synthesize_cells

        return synthesize_cells(abstraction, witness, robot, source=source)
    started = time.perf_counter()
    steps, loop_start = plan_steps(abstraction, witness)
    if robot.disturbance > 0.0:
        # the planner's widest-lasso search, recorded on a plan it could not make realisable
        supported = witness.stats.get(SUPPORTED)
        cells_bound = witness.stats.get(SUPPORTED_CELLS)
        _check_rejectable(
            abstraction,
            steps,
            robot,
            source,
            None if supported is None else float(supported),
            None if cells_bound is None else float(cells_bound),
        )
    push = run_push(robot)
    guides = (
        path_guides(
            abstraction,
            steps,
            loop_start,
            robot.start,
            clearance=label_clearance(robot.max_speed),
            relevant=relevant,
        )
        if follow
        else None
    )
    split = bends(abstraction, steps, loop_start, guides) if guides is not None else {}
    _, jumps = _assign_runs(
        abstraction, steps, loop_start, push=push, max_speed=robot.max_speed, split=split
    )
    affine = [step for step in steps if step.through is None]
    program, column = vertex_program(affine, robot.max_speed, robot.disturbance)
    built = time.perf_counter()
    following: dict[str, float | str] = {"follow_status": "off"}
    followed = None
    if guides is not None and affine:  # (its solve stands in for the vertex program's)
        followed = follow_channel(
            steps, guides, conic_form(program), program.runs, column, robot.max_speed,
            robot.disturbance,
        )  # fmt: skip
        following = {"follow_status": "failed"} if followed is None else followed[1]
    velocities = solve_vertex_program(program)[0] if followed is None else followed[0]
    solved = time.perf_counter()
    controllers = []
    # The exit steps' fields, solved at once (a stay may solve its field twice, on its own).
    exits = {
        index: velocities[[column[r] for r in step.runs]]
        for index, step in enumerate(steps)
        if step.through is None and step.exit_edge is not None
    }
    laws = dict(
        zip(
            exits,
            affine_laws([steps[index].geometry.vertices for index in exits], list(exits.values())),
            strict=True,
        )
    )
    for index, step in enumerate(steps):
        if step.through is not None:
            controllers.append(
                pursuit_controller(
                    index,
                    step,
                    abstraction.vertices[step.through],
                    robot.max_speed,
                    robot.disturbance,
                )
            )
            continue
        if index in exits:
            controllers.append(
                _affine_controller(index, step, exits[index], robot, law=laws[index])
            )
            continue
        w = velocities[[column[r] for r in step.runs]]
        controllers.append(_affine_controller(index, step, w, robot))
    for position, controller in enumerate(controllers):
        if controller.is_vertex:
            continue  # the pursuit law's guarantees hold by construction (docs/control.md)
        # (The step's geometry is that of the controller's own vertex array: not again.)
        own = steps[position].geometry
        problem = violated_condition(controller, robot.max_speed, robot.disturbance, own)
        if problem is None:
            continue
        # A needle: the solver's tolerance swamps the little its sliver corners can push.
        # The best-push field (or a stay's radial field), built from the geometry alone,
        # meets every row to rounding where any field can.
        step = steps[position]
        rebuilt = _geometric_controller(position, step, robot)
        if violated_condition(rebuilt, robot.max_speed, robot.disturbance) is None:
            controllers[position] = rebuilt
            jumps.extend(_own_velocity_jumps(abstraction, steps, position, loop_start))
            continue
        floor = robot.disturbance + RECHECK_TOLERANCE * robot.max_speed
        pushes = [_corner(abstraction, position, step, k, robot.max_speed) for k in range(3)]
        bound = weakest(pushes)
        if bound.push <= floor * (1.0 + RECHECK_TOLERANCE):
            x, y = bound.position
            raise InvalidInputError(
                error(
                    "C050",
                    f"plan step {position} (triangle {step.triangle}) has a corner of "
                    f"{bound.angle:.3g} degrees at ({x:.6g}, {y:.6g}) where no velocity within "
                    f"max_speed pushes more than {bound.push:.3g} along the facets it must: "
                    "not more than the disturbance plus the controllers' stated tolerance "
                    f"(1e-9 x max_speed, {floor:.3g} in all)",
                    hint="a needle triangle: set options.min_angle (e.g. 20) to refine the mesh "
                    "around it; if the corner is a region's or obstacle's own corner this "
                    "sharp, blunt it",
                    file=source,
                )
            )
        raise SolverError(
            error(
                "C030",
                f"plan step {controller.step} (triangle {controller.triangle}): the solved "
                f"field fails the re-check: {problem}",
                hint="please report this mission",
            )
        )
    if any(c.exit_speed <= 0 for c in controllers):
        worst = min(controllers, key=lambda c: c.exit_speed)
        raise SolverError(
            error(
                "C004",
                f"plan step {worst.step} has no positive exit speed",
                hint="the triangle may be degenerate; raise options.min_angle",
            )
        )
    return Controllers(
        steps=tuple(controllers),
        loop_start=loop_start,
        max_speed=robot.max_speed,
        margin=MARGIN,
        jumps=tuple(jumps),
        stats={
            "steps": len(controllers),
            "variables": 2 * program.runs + program.steps,
            "prepare_seconds": round(built - started, 6),
            "solve_seconds": round(solved - built, 6),
            "min_exit_speed": min(c.exit_speed for c in controllers),
            **following,
        },
    )


def _affine_controller(
    index: int,
    step: _Step,
    w: FloatArray,
    robot: Robot,
    *,
    radial: bool = False,
    law: tuple[FloatArray, FloatArray] | None = None,
) -> StepController:
    """The affine field of ``step`` through the vertex velocities ``w`` (for a stay with
    ``radial``, or where the solved field is degenerate, the radial field to the incenter);
    ``law`` is an exit step's ``affine_law(vertices, w)`` when already solved."""
    geometry = step.geometry
    target = None
    if step.exit_edge is None:
        center = geometry.incenter()
        gain, offset = affine_law(geometry.vertices, w)
        inward = min(-geometry.normals[j] @ w[i] for i in range(3) for j in range(3) if j != i)
        if radial or inward <= 0 or np.max(np.linalg.eigvals(gain).real) >= 0:
            # The program's optimum is degenerate here: use the radial field to x*.
            kappa = robot.max_speed / max(np.linalg.norm(center - v) for v in geometry.vertices)
            w = kappa * (center - geometry.vertices)
            inward = min(-geometry.normals[j] @ w[i] for i in range(3) for j in range(3) if j != i)
        gain, offset = affine_law(geometry.vertices, w)
        speed, bound = float(inward), float("inf")
        # The field's own equilibrium (the program puts it at the incenter, to the
        # solver's tolerance): the state converges there, so that is the target.
        equilibrium = np.linalg.solve(gain, -offset)
        target = (float(equilibrium[0]), float(equilibrium[1]))
    else:
        gain, offset = affine_law(geometry.vertices, w) if law is None else law
        nx, ny = geometry.normals[step.exit_edge].tolist()
        delta = min(nx * wx + ny * wy for wx, wy in w.tolist())  # numpy's 2-vector dot
        speed = delta
        # under a disturbance |w| <= d the state still crosses at delta - d or faster
        closing = delta - robot.disturbance
        bound = float(geometry.heights[step.exit_edge] / closing) if closing > 0 else float("inf")
    return StepController(
        step=index,
        triangle=step.triangle,
        exit_edge=step.exit_edge,
        next_triangle=step.next_triangle,
        vertices=geometry.vertices,
        velocities=w,
        gain=gain,
        offset=offset,
        exit_speed=speed,
        exit_time_bound=bound,
        target=target,
    )


def _geometric_controller(index: int, step: _Step, robot: Robot) -> StepController:
    """The field of ``step`` from its geometry alone: the best-push field of an exit step,
    the radial field of a stay (each corner pushes its corner push, see control.robust)."""
    if step.exit_edge is None:
        return _affine_controller(index, step, np.zeros((3, 2)), robot, radial=True)
    rows = [_normals(step, local) for local in range(3)]
    w = np.array(best_push_velocities(rows, robot.max_speed), dtype=np.float64)
    return _affine_controller(index, step, w, robot)


def _own_velocity_jumps(
    abstraction: Abstraction, steps: list[_Step], position: int, loop_start: int | None
) -> list[VelocityJump]:
    """Jumps at the corners step ``position`` shares with its neighbours in the plan, once
    its velocities are its own."""
    reason = "a needle's field is built from its own geometry"
    corners = abstraction.triangles[steps[position].triangle].tolist()
    following = position + 1
    if following == len(steps) and loop_start is not None:
        following = loop_start  # the cycle's wrap
    found = []
    # (the step where the field changes, the neighbour sharing corners with this one)
    for at, neighbour in ((position, position - 1), (following, following)):
        if not 0 <= neighbour < len(steps) or neighbour == position:
            continue
        if steps[neighbour].through is not None:
            continue  # no velocity is shared across a vertex passage
        for vertex in abstraction.triangles[steps[neighbour].triangle].tolist():
            if vertex in corners:
                x, y = abstraction.vertices[vertex].tolist()
                found.append(VelocityJump(step=at, vertex=vertex, position=(x, y), reason=reason))
    return found
