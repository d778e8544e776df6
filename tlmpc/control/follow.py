"""Vertex velocities whose flow follows the channel's shortest path (a second program).

The vertex program (:mod:`tlmpc.control.synthesize`) only asks every state to leave by the
planned facet; its flow wanders from triangle to triangle.  Here the same constraints are kept
and the objective changes.  In each step the channel's shortest path is one straight piece
from an entry point p to an exit point q (:mod:`tlmpc.control.channel`), direction d.  The
field is affine, so if it is parallel to d at p and at q it is parallel to d all along the
segment, which is then a flow line: the robot entering at p leaves at q, on the path.  The
program therefore asks, with a slack t per step,

    |d x f(p)| <= t,  |d x f(q)| <= t            (f(x) = sum_i lambda_i(x) w_i, linear in w)

and maximises the speed along the path minus the misalignment, weighted by each piece's
length (so time, not triangle count, is what it saves):

    sum_k len_k (d·f(p) + d·f(q)) / 2 - ALIGNMENT * len_k t_k

while every guaranteed exit speed stays at least :data:`KEEP_FLOOR` times the one the vertex
program reached (its exit-time bounds grow by at most 1 / KEEP_FLOOR).  A stay has one piece,
from its entry to its target, where the field vanishes: parallel at p suffices.  Where a
bend, a shared vertex velocity or the margins make exact alignment impossible, the slack
stays positive and the flow deviates as little as the objective allows; every vertex
condition, the speed bound and the disturbance rows are the vertex program's own rows,
and the re-check after solving is the same.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray
from tlmpc.control.channel import ChannelStep, Guide, Point, channel_guides
from tlmpc.control.geometry import TriangleGeometry
from tlmpc.control.sparse import CscMatrix, Triplets, stacked_csc

#: Weight of the misalignment slack against the speed along the path.
ALIGNMENT = 10.0
#: The aligned fields keep at least this fraction of the fastest fields' speed along the path
#: at every point where the path is followed.
KEEP_SPEED = 0.9
#: Relative and absolute duality gap at which the following solves stop.
OBJECTIVE_GAP = 1e-4
#: Weight of the vertex program's objective (the guaranteed speeds) in both solves.
GUARANTEE = 1.0
#: Every step's guaranteed exit speed keeps at least this fraction of the vertex program's.
KEEP_FLOOR = 0.5


class ConicLike(Protocol):
    """A conic form (A, b, cones) as :func:`tlmpc.control.synthesize.conic_form` gives it."""

    @property
    def constraints(self) -> CscMatrix: ...
    @property
    def offsets(self) -> FloatArray: ...
    @property
    def cones(self) -> tuple[tuple[str, int], ...]: ...


@dataclass(frozen=True, slots=True)
class FollowStep:
    """An affine step as this program sees it: its triangle, the program column of each local
    vertex's velocity run, and its piece of the path."""

    geometry: TriangleGeometry
    columns: tuple[int, int, int]
    guide: Guide
    stay: bool


@dataclass(frozen=True, slots=True)
class FollowResult:
    """The velocities per run (R, 2) at the program's scale, and how the solve went."""

    velocities: FloatArray
    status: str
    misalignment: float  # the largest slack t (unit speed)


def _csc_triplets(matrix: CscMatrix) -> Triplets:
    cols = np.repeat(np.arange(matrix.shape[1], dtype=np.int64), np.diff(matrix.indptr))
    return Triplets(matrix.indices.astype(np.int64), cols, matrix.data, matrix.shape)


@dataclass(frozen=True, slots=True)
class _Point:
    """A point of the path where the field is asked to run along d: the program columns and
    coefficients of d·f (``along``) and d x f (``across``), its step, its weight."""

    step: int
    columns: list[int]
    along: list[float]
    across: list[float]
    weight: float


def _path_points(follow: Sequence[FollowStep]) -> list[_Point]:
    lengths = [
        float(np.hypot(s.guide.exit[0] - s.guide.entry[0], s.guide.exit[1] - s.guide.entry[1]))
        for s in follow
    ]
    scale = sum(lengths) or 1.0
    points: list[_Point] = []
    for k, (step, length) in enumerate(zip(follow, lengths, strict=True)):
        if length <= 0.0:
            continue  # nothing to follow
        dx = (step.guide.exit[0] - step.guide.entry[0]) / length
        dy = (step.guide.exit[1] - step.guide.entry[1]) / length
        where = [step.guide.entry] if step.stay else [step.guide.entry, step.guide.exit]
        for point in where:
            lambdas = step.geometry.barycentric(np.asarray(point, dtype=np.float64)).tolist()
            columns, along, across = [], [], []
            for local, column in enumerate(step.columns):
                columns += [2 * column, 2 * column + 1]
                along += [dx * lambdas[local], dy * lambdas[local]]
                across += [-dy * lambdas[local], dx * lambdas[local]]  # d x f = dx fy - dy fx
            points.append(_Point(k, columns, along, across, length / scale / len(where)))
    return points


def follow_program(
    constraints: CscMatrix,
    offsets: FloatArray,
    cones: Sequence[tuple[str, int]],
    runs: int,
    steps: int,
    floors: Sequence[float],
    follow: Sequence[FollowStep],
    *,
    alignment: float,
    speeds: Sequence[float] | None = None,
) -> tuple[CscMatrix, FloatArray, FloatArray, list[tuple[str, int]]]:
    """The vertex program's conic form (x = (w, s, f)) extended by one slack t per followed
    step; returns (A, costs, b, cones) for x = (w, s, f, t).

    Minimises ``alignment`` * sum(weight t) - sum(weight d·f) over the path points, with
    |d x f| <= t there, s_k >= KEEP_FLOOR * ``floors[k]`` (the vertex program's guaranteed
    speed of step k, unit speed) and, given ``speeds`` (one per path point), d·f >= that
    speed at each.
    """
    rows_a, size = constraints.shape
    total = size + len(follow)
    points = _path_points(follow)
    rows: list[int] = []
    cols: list[int] = []
    vals: list[float] = []
    bounds: list[float] = []
    costs = np.zeros(total)
    # The vertex program's own objective (floor + a tenth of the mean guaranteed speed) at
    # weight GUARANTEE: without it the fields nobody's path weighs (a stay's, a needle's) sit
    # at the floor, and a stay converges slowly.
    costs[2 * runs + steps] = -GUARANTEE
    costs[2 * runs : 2 * runs + steps] = -0.1 * GUARANTEE / max(steps, 1)
    for point in points:
        slack = size + point.step
        # t >= sign (d x f): A x <= 0 with A = (sign d x, -1); not asked when not weighed
        for sign in (1.0, -1.0) if alignment > 0.0 else ():
            rows += [len(bounds)] * (len(point.columns) + 1)
            cols += [*point.columns, slack]
            vals += [sign * c for c in point.across] + [-1.0]
            bounds.append(0.0)
        for column, coefficient in zip(point.columns, point.along, strict=True):
            costs[column] -= point.weight * coefficient
        costs[slack] += alignment * point.weight
    if speeds is not None:  # d·f >= speed: -(d·f) + s = -speed
        for point, speed in zip(points, speeds, strict=True):
            rows += [len(bounds)] * len(point.columns)
            cols += point.columns
            vals += [-c for c in point.along]
            bounds.append(-speed)
    for k, kept in enumerate(floors):  # s_k >= KEEP_FLOOR * floor_k: -s_k + s = -that
        rows.append(len(bounds))
        cols.append(2 * runs + k)
        vals.append(-1.0)
        bounds.append(-KEEP_FLOOR * kept)
    for k in range(len(follow)):  # t >= 0: -t + s = 0
        rows.append(len(bounds))
        cols.append(size + k)
        vals.append(-1.0)
        bounds.append(0.0)
    base = _csc_triplets(constraints)
    widened = Triplets(base.rows, base.cols, base.values, (rows_a, total))
    extra = Triplets.build(rows, cols, vals, (len(bounds), total))
    matrix = stacked_csc([(0, widened), (rows_a, extra)], (rows_a + len(bounds), total))
    return (
        matrix,
        costs,
        np.concatenate([offsets, np.asarray(bounds)]),
        [*cones, ("nonnegative", len(bounds))],
    )


def _clarabel(
    matrix: CscMatrix, costs: FloatArray, b: FloatArray, cones: Sequence[tuple[str, int]]
) -> FloatArray | None:
    """Clarabel's solution x of min costs·x, A x + s = b, s in the cones; None unless solved."""
    import clarabel

    kinds = {
        "zero": clarabel.ZeroConeT,
        "nonnegative": clarabel.NonnegativeConeT,
        "second-order": clarabel.SecondOrderConeT,
    }
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    # The objective is a heuristic (the path); only the rows are guarantees, and they keep the
    # default feasibility tolerance.  A looser duality gap saves most of the iterations.
    settings.tol_gap_abs = settings.tol_gap_rel = OBJECTIVE_GAP
    total = matrix.shape[1]
    empty = np.zeros(0, dtype=np.int64)
    solver = clarabel.DefaultSolver(
        CscMatrix(np.zeros(0), empty, np.zeros(total + 1, dtype=np.int64), (total, total)),
        costs,
        matrix,
        b,
        [kinds[kind](dim) for kind, dim in cones],
        settings,
    )
    solution = solver.solve()
    if str(solution.status) not in ("Solved", "AlmostSolved"):
        return None
    return np.asarray(solution.x, dtype=np.float64)


def solve_follow(
    constraints: CscMatrix,
    offsets: FloatArray,
    cones: Sequence[tuple[str, int]],
    runs: int,
    steps: int,
    floors: Sequence[float],
    follow: Sequence[FollowStep],
) -> FollowResult | None:
    """Two solves: the fastest fields along the path (no alignment), then the best aligned
    ones that keep :data:`KEEP_SPEED` of that speed at every path point.  None when either
    does not solve (the vertex program's velocities then stand)."""
    common = (constraints, offsets, cones, runs, steps, floors, follow)
    fastest = _clarabel(*follow_program(*common, alignment=0.0))
    if fastest is None:
        return None
    points = _path_points(follow)
    reached = [float(np.dot(fastest[p.columns], p.along)) for p in points]
    # (a point the fastest fields cross against d keeps its speed to the same fraction)
    speeds = [v - (1.0 - KEEP_SPEED) * abs(v) for v in reached]
    x = _clarabel(*follow_program(*common, alignment=ALIGNMENT, speeds=speeds))
    if x is None:
        return None
    slacks = x[constraints.shape[1] :]
    return FollowResult(
        velocities=x[: 2 * runs].reshape(runs, 2),
        status="Solved",
        misalignment=float(slacks.max()) if len(slacks) else 0.0,
    )


class PlanStep(Protocol):
    """What :func:`follow_channel` reads of a plan step of the vertex program."""

    triangle: int
    exit_edge: int | None
    geometry: TriangleGeometry
    runs: list[int]
    through: int | None


def follow_channel(
    abstraction: Abstraction,
    steps: Sequence[PlanStep],
    loop_start: int | None,
    start: tuple[float, float],
    form: ConicLike,
    runs: int,
    column: Mapping[int, int],
    speeds: FloatArray,
    max_speed: float,
    disturbance: float,
) -> tuple[FloatArray, dict[str, float | str]] | None:
    """Velocities per run (R, 2, at ``max_speed``) whose flow follows the channel's shortest
    path, and stats; None when the following program does not solve.

    ``form`` is the vertex program's conic form, ``speeds`` its solution's guaranteed speeds.
    """
    # A vertex is on a label boundary when the triangles around it do not all share a label.
    letters = np.repeat(abstraction.letter_of, 3)  # each corner's triangle's letter
    count = len(abstraction.vertices)
    lowest = np.full(count, np.iinfo(np.int64).max)
    highest = np.full(count, -1)
    np.minimum.at(lowest, abstraction.triangles.reshape(-1), letters)
    np.maximum.at(highest, abstraction.triangles.reshape(-1), letters)
    boundary = (lowest != highest).tolist()
    label = abstraction.letter_of.tolist()
    channel = [
        ChannelStep(
            labelled=_flags([boundary[v] for v in abstraction.triangles[step.triangle].tolist()]),
            entered=index > 0 and label[step.triangle] != label[steps[index - 1].triangle],
            corners=_corners(step.geometry.vertices),
            exit_edge=step.exit_edge,
            through=None if step.through is None else _point(abstraction.vertices[step.through]),
        )
        for index, step in enumerate(steps)
    ]
    guides = channel_guides(channel, loop_start, start)
    affine = [(step, guide) for step, guide in zip(steps, guides, strict=True)]
    follow = [
        FollowStep(
            geometry=step.geometry,
            columns=(column[step.runs[0]], column[step.runs[1]], column[step.runs[2]]),
            guide=guide,
            stay=step.exit_edge is None,
        )
        for step, guide in affine
        if step.through is None and guide is not None and not _needle(step.geometry)
    ]
    floors = (speeds / max_speed).tolist()
    result = solve_follow(
        form.constraints, form.offsets, form.cones, runs, len(speeds), floors, follow
    )
    if result is None:
        return None
    velocities = result.velocities * max_speed
    # As for the vertex program: the solver meets |w| <= 1 only to its tolerance; the other
    # rows are homogeneous without a disturbance, so one common shrink keeps them.
    largest = float(np.linalg.norm(velocities, axis=1).max()) if runs else 0.0
    if largest > max_speed and disturbance == 0.0:
        velocities = velocities * (max_speed / largest * (1.0 - 4 * np.finfo(np.float64).eps))
    return velocities, {"follow_status": result.status, "misalignment": result.misalignment}


def _corners(vertices: FloatArray) -> tuple[Point, Point, Point]:
    (ax, ay), (bx, by), (cx, cy) = vertices.tolist()
    return ((ax, ay), (bx, by), (cx, cy))


def _point(vertex: FloatArray) -> Point:
    x, y = vertex.tolist()
    return (x, y)


#: A triangle whose smallest height is below this fraction of its longest edge is a needle:
#: a field turned toward the path across it changes by O(1) over its tiny width, a gain so
#: large that the exact simulation's matrix exponential overflows.  Needles are not asked to
#: follow the path: their fields only keep the vertex conditions (and the floor).
NEEDLE = 0.05


def _needle(geometry: TriangleGeometry) -> bool:
    corners = geometry.vertices.tolist()
    longest = max(
        float(np.hypot(corners[i][0] - corners[i - 1][0], corners[i][1] - corners[i - 1][1]))
        for i in range(3)
    )
    return bool(float(geometry.heights.min()) < NEEDLE * longest)


def _flags(values: list[bool]) -> tuple[bool, bool, bool]:
    return (values[0], values[1], values[2])
