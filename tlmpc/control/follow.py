"""Vertex velocities whose flow follows the channel's shortest path (the vertex program's rows,
another objective).

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

plus the vertex program's own objective (the guaranteed speeds, the smallest weighted most,
so the weakest step's exit-time bound stays the vertex program's).  It is solved *instead of*
the vertex program (same rows, one Clarabel solve); where the path bends across a portal the
velocity runs are split beforehand (:func:`bends`), since a velocity shared at both ends of
a portal makes the two fields equal along it and the flow could not turn there.  A stay is
not asked to follow its piece (the task is met where it is entered): its field keeps the
vertex program's objective, which converges to its target fastest (asked to follow a piece
from where the path enters it, at the nearest point of its entry edge, the reach-avoid spec's
stay was guaranteed 0.015 x max_speed inward, the vertex program's own fields 0.07).
Where a shared vertex velocity or the margins make exact alignment impossible, the slack
stays positive and the flow deviates as little as the objective allows; every vertex
condition, the speed bound and the disturbance rows are the vertex program's own rows,
and the re-check after solving is the same.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.control.channel import ChannelStep, Guide, Point, channel_guides, channel_pieces
from tlmpc.control.clearance import exposed_vertices, label_boundary
from tlmpc.control.geometry import TriangleGeometry
from tlmpc.control.sparse import CscMatrix, Triplets, stacked_csc

#: Weight of the misalignment slack against the speed along the path.  Below 1 a field
#: never trades speed for alignment at a loss (a field of speed v at angle θ to the path
#: scores v (cos θ - ALIGNMENT sin θ)): the flow keeps speed and turns where the rows allow.
ALIGNMENT = 0.5
#: Relative and absolute duality gap at which the following solve stops.
OBJECTIVE_GAP = 1e-4
#: Weight of the vertex program's objective (the guaranteed speeds).
GUARANTEE = 1.0
#: ... and the floor (the smallest guaranteed speed) this many times more.
FLOOR_WEIGHT = 10.0
#: ... but only up to this fraction of max_speed for a robot with a declared disturbance
#: (beyond the disturbance: the guaranteed speeds are what is left of the velocity across
#: the exit facet under the worst disturbance).  Uncapped, a floor that the split velocity
#: runs (:func:`bends`) raise drew every step's exit speed up to it, turning the fields off
#: the path to push across their exit facets (a regular grid's fields crossed at 37° to
#: their pieces).  The weakest step keeps the vertex program's floor where that is lower,
#: and at least this otherwise (at 0.1 and 0.15 a corridor's robot pushed at 16 times its
#: declared disturbance no longer completed its laps in one run of eight).
FLOOR_CAP = 0.2
#: ... and this fraction for a robot without one (``robot.disturbance`` 0): no push is
#: claimed there, the floor only bounds the exit time, and a floor at 0.2 held the weakest
#: step (on Example 1, one in a fan round an obstacle's corner) to push across its exit
#: facet rather than along the path (on the bench at 0.2 the lengths were up to 1.8 % and
#: the times up to 2.1 % longer; docs/performance.md).
FREE_FLOOR_CAP = 0.1


def floor_cap(disturbance: float) -> float:
    """The fraction of max_speed up to which the following program rewards the smallest
    guaranteed exit speed: :data:`FLOOR_CAP` under a declared disturbance,
    :data:`FREE_FLOOR_CAP` without one."""
    return FLOOR_CAP if disturbance > 0.0 else FREE_FLOOR_CAP


class ConicLike(Protocol):
    """A conic form (A, q, b, cones) as :func:`tlmpc.control.synthesize.conic_form` gives it."""

    @property
    def constraints(self) -> CscMatrix: ...
    @property
    def costs(self) -> FloatArray: ...
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
class _PathPoints:
    """The points of the path where the field is asked to run along d, one row each: their
    step (index into the followed steps), the program columns (w_x, w_y of the three corners)
    and coefficients of d·f (``along``) and d x f (``across``) there, and their weight."""

    step: IntArray  # (P,)
    columns: IntArray  # (P, 6)
    along: FloatArray  # (P, 6)
    across: FloatArray  # (P, 6)
    weight: FloatArray  # (P,)


def _path_points(follow: Sequence[FollowStep]) -> _PathPoints:
    """Each followed step's entry and exit points, in step order, weighted by the step's
    share of the path's length (so time, not triangle count, counts)."""
    count = len(follow)
    if count == 0:
        empty = np.zeros((0, 6))
        return _PathPoints(
            np.zeros(0, dtype=np.int64), np.zeros((0, 6), dtype=np.int64), empty, empty, np.zeros(0)
        )
    entry = np.array([s.guide.entry for s in follow], dtype=np.float64).reshape(count, 2)
    exit_ = np.array([s.guide.exit for s in follow], dtype=np.float64).reshape(count, 2)
    normals = np.array([s.geometry.normals for s in follow], dtype=np.float64)
    offsets = np.array([s.geometry.offsets for s in follow], dtype=np.float64)
    heights = np.array([s.geometry.heights for s in follow], dtype=np.float64)
    columns = np.array([s.columns for s in follow], dtype=np.int64).reshape(count, 3)
    delta = exit_ - entry
    lengths = np.hypot(delta[:, 0], delta[:, 1])
    scale = float(lengths.sum()) or 1.0
    moving = lengths > 0.0  # a piece of no length has nothing to follow
    # Rows in step order: entry then exit.
    steps = np.concatenate([np.flatnonzero(moving), np.flatnonzero(moving)])
    where = np.concatenate([entry[moving], exit_[moving]])
    order = np.argsort(steps, kind="stable")
    steps, where = steps[order], where[order]
    lambdas = (offsets[steps] - np.einsum("pij,pj->pi", normals[steps], where)) / heights[steps]
    safe = np.where(moving, lengths, 1.0)
    dx, dy = (delta[:, 0] / safe)[steps], (delta[:, 1] / safe)[steps]
    pair = np.stack([2 * columns[steps], 2 * columns[steps] + 1], axis=2).reshape(-1, 6)
    along = np.stack([dx[:, None] * lambdas, dy[:, None] * lambdas], axis=2).reshape(-1, 6)
    # d x f = dx fy - dy fx
    across = np.stack([-dy[:, None] * lambdas, dx[:, None] * lambdas], axis=2).reshape(-1, 6)
    weight = lengths[steps] / scale / 2.0
    return _PathPoints(steps, pair, along, across, weight)


def follow_program(
    constraints: CscMatrix,
    offsets: FloatArray,
    cones: Sequence[tuple[str, int]],
    runs: int,
    steps: int,
    follow: Sequence[FollowStep],
    *,
    alignment: float,
    floor_cap: float,
) -> tuple[CscMatrix, FloatArray, FloatArray, list[tuple[str, int]]]:
    """The vertex program's conic form (x = (w, s, f)) extended by one slack t per followed
    step; returns (A, costs, b, cones) for x = (w, s, f, t).

    Minimises ``alignment`` * sum(weight t) - sum(weight d·f) over the path points, with
    |d x f| <= t there, minus the vertex program's own objective (:data:`GUARANTEE`,
    :data:`FLOOR_WEIGHT`).
    """
    rows_a, size = constraints.shape
    total = size + len(follow)
    points = _path_points(follow)
    count = len(points.step)
    costs = np.zeros(total)
    # The vertex program's own objective (floor + a tenth of the mean guaranteed speed) at
    # weight GUARANTEE: without it the fields nobody's path weighs (a stay's, a needle's) sit
    # at the floor, and a stay converges slowly.  The floor weighs FLOOR_WEIGHT times more:
    # this solve stands in for the vertex program, whose floor it then keeps (the
    # weakest step's exit-time bound is the run's longest).
    costs[2 * runs + steps] = -FLOOR_WEIGHT * GUARANTEE
    costs[2 * runs : 2 * runs + steps] = -0.1 * GUARANTEE / max(steps, 1)
    np.add.at(costs, points.columns.ravel(), -(points.weight[:, None] * points.along).ravel())
    np.add.at(costs, size + points.step, alignment * points.weight)
    blocks: list[tuple[FloatArray, IntArray, FloatArray]] = []  # (values, columns, bounds)
    slack = (size + points.step)[:, None]
    minus = -np.ones((count, 1))
    for sign in (1.0, -1.0) if alignment > 0.0 else ():
        # t >= sign (d x f): sign (d x f) - t + s = 0; not asked when not weighed
        blocks.append(
            (
                np.hstack([sign * points.across, minus]),
                np.hstack([points.columns, slack]),
                np.zeros(count),
            )
        )
    blocks.append(  # t >= 0: -t + s = 0
        (-np.ones((len(follow), 1)), size + np.arange(len(follow))[:, None], np.zeros(len(follow)))
    )
    # f <= floor_cap: f + s = floor_cap
    blocks.append((np.ones((1, 1)), np.array([[2 * runs + steps]]), np.array([floor_cap])))
    rows, cols, vals, bounds, start = [], [], [], [], 0
    for values, columns, bound in blocks:
        height, width = values.shape
        rows.append(np.repeat(np.arange(start, start + height), width))
        cols.append(columns.ravel())
        vals.append(values.ravel())
        bounds.append(bound)
        start += height
    base = _csc_triplets(constraints)
    widened = Triplets(base.rows, base.cols, base.values, (rows_a, total))
    extra = Triplets.build(
        np.concatenate(rows), np.concatenate(cols), np.concatenate(vals), (start, total)
    )
    matrix = stacked_csc([(0, widened), (rows_a, extra)], (rows_a + start, total))
    return (
        matrix,
        costs,
        np.concatenate([offsets, *bounds]),
        [*cones, ("nonnegative", start)],
    )


def _clarabel(
    matrix: CscMatrix,
    costs: FloatArray,
    b: FloatArray,
    cones: Sequence[tuple[str, int]],
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
    # Refining each KKT solve buys the search directions digits that neither the heuristic
    # objective nor the rows need: the solver's stopping test reads the residuals themselves,
    # and every field is checked against its rows after the solve.  It was a third of the
    # solve on large plans.
    settings.iterative_refinement_enable = False
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
    follow: Sequence[FollowStep],
    floor_cap: float,
) -> FollowResult | None:
    """One solve of :func:`follow_program` at :data:`ALIGNMENT`; None when it does not
    solve (the vertex program is then solved on its own)."""
    common = (constraints, offsets, cones, runs, steps, follow)
    x = _clarabel(*follow_program(*common, alignment=ALIGNMENT, floor_cap=floor_cap))
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


def path_guides(
    abstraction: Abstraction,
    steps: Sequence[PlanStep],
    loop_start: int | None,
    start: tuple[float, float],
    *,
    clearance: float,
    passages: bool = False,
    relevant: Collection[str] | None = None,
) -> list[Guide | None]:
    """The channel's shortest path, one straight piece per step (None for a vertex
    passage, unless ``passages``: then its piece to the corner), with the portal insets of
    :mod:`tlmpc.control.channel` (``clearance``: the distance kept from a region's own
    boundary, :attr:`tlmpc.control.channel.ChannelStep.clearance`; a compile passes
    :func:`tlmpc.control.channel.label_clearance` of the robot's max_speed)."""
    # A vertex on a label boundary needs an inset only where it is a region's own boundary
    # (tlmpc.control.clearance).
    # Where the plan enters a new label in a triangle by a wall, the path still leaves it
    # through the middle of its exit edge: entering a goal by a wall, or leaving it along one,
    # the path would otherwise hug the wall (robustness is also the distance to leaving the
    # workspace; pushed past the declared disturbance, runs then left it).
    corners = [abstraction.triangles[step.triangle].tolist() for step in steps]
    boundary = label_boundary(abstraction)
    exposed = exposed_vertices(
        abstraction, (v for c in corners for v in c if boundary[v]), relevant
    )
    on_wall = np.zeros(len(abstraction.vertices), dtype=bool)
    rows, sides = np.nonzero(abstraction.neighbors < 0)  # edge i is opposite corner i
    for shift in (1, 2):
        on_wall[abstraction.triangles[rows, (sides + shift) % 3]] = True
    walls = on_wall.tolist()
    flags = [_flags([v in exposed for v in c]) for c in corners]
    near = [any(walls[v] for v in c) for c in corners]
    label = abstraction.letter_of.tolist()
    channel = [
        ChannelStep(
            labelled=flags[index],
            entered=index > 0
            and label[step.triangle] != label[steps[index - 1].triangle]
            and (any(flags[index]) or near[index]),
            by_wall=near[index],
            clearance=clearance,
            corners=_corners(step.geometry.vertices),
            exit_edge=step.exit_edge,
            through=None if step.through is None else _point(abstraction.vertices[step.through]),
        )
        for index, step in enumerate(steps)
    ]
    if passages:
        return list(channel_pieces(channel, loop_start, start))
    return channel_guides(channel, loop_start, start)


#: The path bends across a portal when the sine of the angle between the pieces on its two
#: sides exceeds this (about 1.7°; sharing a velocity across a smaller turn cost nothing
#: measurable, and each split is a reported velocity jump).
BEND = 0.03
#: Why a velocity run is split where the followed path bends.
BENDS = "the path to follow bends across this edge"
#: A vertex's velocity run is also split where sharing its velocity with the run so far
#: would turn the velocity further than this (radians, about 10°) from some step's piece
#: of the path than that step's own rows at the vertex do (smaller thresholds, 5° and 2°,
#: measured the same times on the bench with more jumps).
DEFLECTION = 0.17
#: ... and why.
DEFLECTS = "a velocity shared across this edge would turn a field away from the path"


def bends(
    abstraction: Abstraction,
    steps: Sequence[PlanStep],
    loop_start: int | None,
    guides: Sequence[Guide | None],
) -> dict[tuple[int, int], str]:
    """(step, mesh vertex) pairs where step's field should not share the vertex's velocity
    with the step before, and why: the two ends of a portal across which the path bends
    (:data:`BENDS`), and the vertices where sharing would turn a field away from its piece of
    the path (:data:`DEFLECTS`, :func:`deflections`).

    A velocity shared by both steps at both ends of a portal makes the two fields equal all
    along it; the path's crossing point would then need one direction on both sides, and the
    flow could only turn gradually, triangles away from the bend.  A stay has its own
    velocities already.
    """
    split: dict[tuple[int, int], str] = {}
    pairs = [(index - 1, index) for index in range(1, len(steps))]
    if loop_start is not None:
        pairs.append((len(steps) - 1, loop_start))  # the cycle's wrap
    for before, after in pairs:
        first, second = guides[before], guides[after]
        if first is None or second is None or steps[after].exit_edge is None:
            continue
        if abs(turn_sine(first, second)) <= BEND:
            continue
        shared = set(abstraction.triangles[steps[before].triangle].tolist())
        for vertex in abstraction.triangles[steps[after].triangle].tolist():
            if vertex in shared:
                split[(after, vertex)] = BENDS
    for pair in deflections(abstraction, steps, guides, frozenset(split)):
        split[pair] = DEFLECTS
    return split


#: An arc of the unit circle: its start angle and its width (radians, width <= pi).
_Arc = tuple[float, float]
#: A run as :func:`deflections` tracks it: the arc of directions its velocity may take, and
#: each of its steps' (direction of its piece, deviation its own rows force).
_Run = tuple[_Arc | None, list[tuple[float, float]]]
_TAU = 2.0 * math.pi


def deflections(
    abstraction: Abstraction,
    steps: Sequence[PlanStep],
    guides: Sequence[Guide | None],
    split: frozenset[tuple[int, int]] = frozenset(),
) -> set[tuple[int, int]]:
    """(step, vertex) pairs where the velocity run of the vertex is better split: shared
    with the run so far, the velocity would be turned more than :data:`DEFLECTION` further
    from some step's piece of the path than that step's own rows turn it.

    A vertex velocity w of a step must satisfy a·w >= 0 (margins aside) for the inward
    normals of the non-exit facets through the vertex and the exit facet's outward normal; a
    run's velocity must satisfy every step's, so its direction lies in the intersection of
    their half-circles, an arc.  Where a step's piece of the path points out of that arc (a
    corner's wedge the path does not pass through, shared with the steps before it), the
    fields of the run mix a velocity turned away from the path into their flow and slow
    down: on a bench office the robot crossed a room at 76 % of max_speed beside a wall's
    end whose last triangle's wedge pointed 56° off the path.  ``split``: pairs split
    already (a new run starts there).  A heuristic on where velocity jumps buy speed, not a
    bound; every jump is a transversal switch (docs/control.md, Continuity).
    """
    found: set[tuple[int, int]] = set()
    previous: dict[int, _Run] = {}  # per mesh vertex of the step before: its run
    for index, step in enumerate(steps):
        if step.through is not None or step.exit_edge is None:
            previous = {}  # a vertex passage or a stay: nothing shared across it
            continue
        direction = _direction(guides[index])
        # each facet's half-circle of directions u with a·u >= 0, a its outward normal: the
        # arc starting a quarter turn before a
        outward = [math.atan2(ny, nx) - 0.5 * math.pi for nx, ny in step.geometry.normals.tolist()]
        current: dict[int, _Run] = {}
        for local, vertex in enumerate(abstraction.triangles[step.triangle].tolist()):
            arc = _vertex_arc(outward, local, step.exit_edge)
            own = [] if direction is None else [(direction, _deviation(direction, arc))]
            current[vertex] = (arc, own)
            run = previous.get(vertex)
            if run is None or (index, vertex) in split:
                continue
            joined = _intersect(run[0], arc)
            if joined is None:
                continue  # no common velocity: the runs split there for their own reason
            wanted = run[1] + own
            if any(_deviation(d, joined) - alone > DEFLECTION for d, alone in wanted):
                found.add((index, vertex))
            else:
                current[vertex] = (joined, wanted)
        previous = current
    return found


def _direction(guide: Guide | None) -> float | None:
    """The angle of a piece of the path (None for none or a point)."""
    if guide is None:
        return None
    dx, dy = guide.exit[0] - guide.entry[0], guide.exit[1] - guide.entry[1]
    return None if dx == 0.0 and dy == 0.0 else math.atan2(dy, dx)


def _vertex_arc(outward: list[float], local: int, exit_edge: int) -> _Arc | None:
    """The directions u with a·u >= 0 for every direction a the vertex program's rows ask of
    the velocity at local vertex ``local`` (their margins aside): inward across the non-exit
    facets through it, across the exit facet; ``outward``: the start of each facet's
    half-circle across it.  None when only the zero vector is left."""
    arc: _Arc | None = (outward[exit_edge], math.pi)
    for facet in range(3):
        if facet != local and facet != exit_edge:  # inward: the opposite half-circle
            arc = _intersect(arc, (outward[facet] + math.pi, math.pi))
    return arc


def _intersect(first: _Arc | None, second: _Arc | None) -> _Arc | None:
    """The arc common to two arcs, each at most a half-circle wide; None when they share no
    arc."""
    if first is None or second is None:
        return None
    (start, width), (other, other_width) = first, second
    ahead = (other - start) % _TAU  # where the second starts, measured from the first
    if ahead <= width:
        end = min(width, ahead + other_width)
        return (other, end - ahead) if end > ahead else None
    behind = (start - other) % _TAU
    if behind <= other_width:
        end = min(other_width, behind + width)
        return (start, end - behind) if end > behind else None
    return None


def _deviation(direction: float, arc: _Arc | None) -> float:
    """The angle from ``direction`` to the nearest direction in ``arc`` (inf for none)."""
    if arc is None:
        return math.inf
    start, width = arc
    ahead = (direction - start) % _TAU
    if ahead <= width:
        return 0.0
    return min(ahead - width, _TAU - ahead)


def turn_sine(first: Guide, second: Guide) -> float:
    """The sine of the angle from the direction of ``first`` to that of ``second`` (0 when
    either piece is a point)."""
    ax, ay = first.exit[0] - first.entry[0], first.exit[1] - first.entry[1]
    bx, by = second.exit[0] - second.entry[0], second.exit[1] - second.entry[1]
    norms = math.hypot(ax, ay) * math.hypot(bx, by)
    return (ax * by - ay * bx) / norms if norms > 0.0 else 0.0


def follow_channel(
    steps: Sequence[PlanStep],
    guides: Sequence[Guide | None],
    form: ConicLike,
    runs: int,
    column: Mapping[int, int],
    max_speed: float,
    disturbance: float,
) -> tuple[FloatArray, dict[str, float | str]] | None:
    """Velocities per run (R, 2, at ``max_speed``) whose flow follows ``guides`` (the
    channel's shortest path, :func:`path_guides`), and stats; None when the following program
    does not solve.

    ``form`` is the vertex program's conic form (``steps`` guaranteed speeds).
    """
    follow = [
        FollowStep(
            geometry=step.geometry,
            columns=(column[step.runs[0]], column[step.runs[1]], column[step.runs[2]]),
            guide=guide,
        )
        for step, guide in zip(steps, guides, strict=True)
        if step.through is None
        and step.exit_edge is not None
        and guide is not None
        and not _needle(step.geometry)
    ]
    result = solve_follow(
        form.constraints,
        form.offsets,
        form.cones,
        runs,
        len(form.costs) - 2 * runs - 1,
        follow,
        floor_cap(disturbance),
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
