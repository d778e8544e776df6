"""Proofs that no trajectory meets a deadline: the earliest time a task's goals can be reached.

The robot moves at speed at most ``max_speed + disturbance`` (the controllers keep
``|u| <= max_speed``), so no trajectory reaches a goal sooner than the length of the shortest
path to it, inside the free space the task's invariants leave (``G !hazard`` removes the
hazard), divided by that speed.  For the fragment where that decides the question this module
finds the shortest such paths and turns every deadline they cannot meet into a proof:

* a **deadline from the start** ``F[0,T] p`` (``visit p within T s``), and a **sequence**
  ``F[0,T1](p1 & F[0,T2](p2 & ...))``: p1 is reached no sooner than the shortest path into
  it, each later goal no sooner than that plus the ways between the goals before it (against
  ``T1 + ... + Tj``), and each way from one goal to the next takes its own time (against
  ``Tj``);
* a **conjunction of deadlines** ``F[0,T1] p1 & F[0,T2] p2 & ...`` (up to
  :data:`MAX_ORDERS_OF` of them): the goals are first reached in some order; the task is
  impossible when every order misses one of its deadlines;
* a **revisit period** ``G F[0,T] p`` (``visit p at least every T s``): the first visit is a
  deadline from the start, and when the task also makes the robot visit another region q
  again and again, every trip from p to q and back is at least twice the way between them.

The shortest path from the start into a goal is exact (to a tolerance): it bends only at
reflex corners of the free space and ends at a corner of the goal or at the foot of its last
corner on an edge of the goal, so a search over those corners (their mutual visibility tested
on the free space grown by :data:`TOLERANCE`, which only ever adds segments) finds it.  The
way between two goals is bounded from below: a path through the corners, or one straight
segment no shorter than the distance between the goals.  Past :data:`MAX_CORNERS` corners
every path is a straight line (obstacles ignored).  Every number here is a lower bound on the
true time, lowered again by the tolerance, so a deadline below it cannot be met: a proof.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import shapely

from tlmpc.abstraction.model import Abstraction, FloatArray
from tlmpc.automata.guards import holds
from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    Eventually,
    Formula,
    Globally,
    Span,
    is_propositional,
)
from tlmpc.ltl.bounds import untimed_skeleton
from tlmpc.ltl.printer import to_text
from tlmpc.mission.model import Mission
from tlmpc.planning.explain import invariant_mask

#: Past this many path corners (start, reflex corners of the free space, goal corners) the
#: search would test too many segments: the shortest paths are taken as straight lines.
MAX_CORNERS = 400
#: A conjunction of at most this many deadlines from the start is checked order by order.
MAX_ORDERS_OF = 4
#: Relative tolerance: segments within this fraction of the map's size of the free space
#: count as inside it, and every bound is lowered by it (a proof never rests on rounding).
TOLERANCE = 1e-9


@dataclass(frozen=True, slots=True, kw_only=True)
class DeadlineBound:
    """A lower bound on the time a deadline of the task needs: a proof that no trajectory of
    the robot meets it when :attr:`proven`.

    ``earliest`` (seconds) is a lower bound on the time the task's ``conjunct`` needs, as
    ``distance`` (map units) at ``speed``; ``deadline`` is what the task allows; ``what``
    says what must be done in that time.
    """

    conjunct: str
    what: str
    deadline: float
    earliest: float
    distance: float
    speed: float
    span: Span | None = None
    #: The top-level conjunct of the task the proof is about (the first, for several).
    anchor: str = ""
    #: The bounded operator (as printed) whose own window ``deadline`` is, when it is one
    #: operator's (empty for sums of windows and for several deadlines together).
    operator: str = ""

    @property
    def proven(self) -> bool:
        """True when the deadline cannot be met: it comes before the earliest time."""
        return self.earliest > self.deadline

    @property
    def message(self) -> str:
        """The proof in words."""
        earliest, deadline = _apart(self.earliest, self.deadline)
        return (
            f"no plan meets the deadline of `{self.conjunct}`: {self.what} takes at least "
            f"{earliest} s > {deadline} s (a path of at least "
            f"{self.distance:.4g} at speed {self.speed:g})"
        )


def _apart(larger: float, smaller: float) -> tuple[str, str]:
    """Two times written with the fewest significant digits (four at least) that show them
    apart: a bound of 16.8231 s over a deadline of 16.82 s is not '16.82 s > 16.82 s'."""
    for digits in range(4, 17):
        texts = (f"{larger:.{digits}g}", f"{smaller:.{digits}g}")
        if texts[0] != texts[1]:
            return texts
    return f"{larger!r}", f"{smaller!r}"


@dataclass(frozen=True, slots=True)
class _Goal:
    """A propositional goal as a point set: where it can hold (see :func:`_goal`; a superset,
    so distances to it are never too long), its boundary segments and their ends."""

    name: str
    shape: shapely.Geometry
    edges: FloatArray  # (k, 2, 2): boundary segments (a lone point: a segment of length 0)
    corners: FloatArray  # (2k, 2): their ends


def _chain(formula: Formula) -> list[tuple[Formula, float | None]] | None:
    """``p1 & F[0,T2](p2 & ...)`` as ``[(p1, None), (p2, T2), ...]`` (an unbounded ``F``
    step: ``T = None``, the chain ends there); None outside the fragment."""
    found = _chain_operators(formula)
    return None if found is None else [(goal, window) for goal, window, _ in found]


def _chain_operators(formula: Formula) -> list[tuple[Formula, float | None, str]] | None:
    """:func:`_chain` with the bounded operator (as printed) that brings each step's window
    (empty for the first step and unbounded ones)."""
    steps: list[tuple[Formula, float | None, str]] = []
    current: Formula | None = formula
    window: float | None = None
    operator = ""
    while current is not None:
        if is_propositional(current):
            steps.append((current, window, operator))
            return steps
        if not isinstance(current, And):
            return None
        goals = [a for a in current.args if is_propositional(a)]
        rest = [a for a in current.args if not is_propositional(a)]
        if len(rest) != 1 or not goals:
            return None
        goal = goals[0] if len(goals) == 1 else And(tuple(goals))
        steps.append((goal, window, operator))
        nxt = rest[0]
        if isinstance(nxt, BoundedEventually) and nxt.interval.low == 0.0:
            current, window, operator = nxt.arg, nxt.interval.high, to_text(nxt)
        elif isinstance(nxt, Eventually):
            current, window, operator = nxt.arg, None, ""
        else:
            return None
    return steps  # pragma: no cover - the loop returns


class _Free:
    """The free space the task's invariants leave, as triangles of a mesh, with the corners a
    shortest path may bend at and a visibility test that only ever adds segments."""

    def __init__(self, abstraction: Abstraction, allowed: np.ndarray, start: tuple[float, float]):
        self.abstraction = abstraction
        self.allowed = allowed
        points = abstraction.vertices
        tris = abstraction.triangles[allowed]
        polygons = [shapely.Polygon(points[t]) for t in tris]
        union = shapely.union_all(polygons) if polygons else shapely.Polygon()
        low, high = points.min(axis=0), points.max(axis=0)
        self.scale = float(max(np.hypot(*(high - low)), 1e-12))
        self.space = union.buffer(TOLERANCE * self.scale)
        shapely.prepare(self.space)
        self.start = np.array(start, dtype=float)
        self.reflex = _reflex_corners(abstraction, allowed)

    def visible(self, a: FloatArray, b: FloatArray) -> np.ndarray:
        """(n,) whether each segment a[i] -> b[i] lies in the free space (up to tolerance)."""
        if not len(a):
            return np.zeros(0, dtype=bool)
        lines = shapely.linestrings(np.stack([a, b], axis=1))
        return np.asarray(shapely.covers(self.space, lines), dtype=bool)


def _reflex_corners(abstraction: Abstraction, allowed: np.ndarray) -> FloatArray:
    """Corners of the free space where its inside angle exceeds 180 degrees."""
    points = abstraction.vertices
    tris = abstraction.triangles[allowed]
    angle = np.zeros(len(points))
    for i in range(3):
        here = points[tris[:, i]]
        u = points[tris[:, (i + 1) % 3]] - here
        v = points[tris[:, (i + 2) % 3]] - here
        cos = np.einsum("ij,ij->i", u, v) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        np.add.at(angle, tris[:, i], np.arccos(np.clip(cos, -1.0, 1.0)))
    # A corner on the boundary: an edge of an allowed triangle with no allowed neighbour.
    neighbors = abstraction.neighbors[allowed]
    outside = (neighbors < 0) | ~allowed[np.maximum(neighbors, 0)]
    on_boundary = np.zeros(len(points), dtype=bool)
    for i in range(3):
        for corner in ((i + 1) % 3, (i + 2) % 3):
            on_boundary[tris[outside[:, i], corner]] = True
    reflex = on_boundary & (angle > math.pi + 1e-9)
    return np.asarray(points[reflex], dtype=float)


def _goal(free: _Free, proposition: Formula, convention: str) -> _Goal:
    """Where ``proposition`` can hold: the allowed triangles whose label satisfies it and,
    under the closed convention, the edges and corners of allowed triangles where the labels
    of the triangles meeting there do (a boundary point carries every region touching it)."""
    abstraction = free.abstraction
    letters = abstraction.letters
    ok_letter = np.array([holds(proposition, set(letter)) for letter in letters], dtype=bool)
    chosen = free.allowed & ok_letter[abstraction.letter_of]
    tris = abstraction.triangles[chosen]
    points = abstraction.vertices
    parts = [shapely.Polygon(points[t]) for t in tris]
    if convention == "closed":
        # where the label alone fails, a boundary point may still carry the regions of every
        # triangle touching it: the edges and corners of allowed triangles where it holds
        regions_at: list[set[str]] = [set() for _ in range(len(points))]
        for t, corners in enumerate(abstraction.triangles.tolist()):
            for v in corners:
                regions_at[v].update(abstraction.labels(t))
        for t in np.flatnonzero(free.allowed & ~chosen).tolist():
            own = set(abstraction.labels(t))
            corners = abstraction.triangles[t].tolist()
            for i, n in enumerate(abstraction.neighbors[t].tolist()):
                if n >= 0 and holds(proposition, own | set(abstraction.labels(n))):
                    ends = [corners[(i + 1) % 3], corners[(i + 2) % 3]]
                    parts.append(shapely.LineString(points[ends]))
            parts.extend(
                shapely.Point(points[v]) for v in corners if holds(proposition, regions_at[v])
            )
    shape = shapely.union_all(parts) if parts else shapely.Polygon()
    edges: list[list[list[float]]] = []
    for part in shapely.get_parts(shape):
        if isinstance(part, shapely.Point):
            edges.append([[part.x, part.y], [part.x, part.y]])
            continue
        lines = (
            shapely.get_parts(shapely.boundary(part))
            if isinstance(part, shapely.Polygon)
            else [part]
        )
        for line in lines:
            coords = shapely.get_coordinates(line)
            edges.extend(
                [coords[k].tolist(), coords[k + 1].tolist()] for k in range(len(coords) - 1)
            )
    corners = np.array([e[0] for e in edges] + [e[1] for e in edges], dtype=float).reshape(-1, 2)
    return _Goal(
        to_text(proposition), shape, np.array(edges, dtype=float).reshape(-1, 2, 2), corners
    )


class _Paths:
    """Shortest paths from the start to goals and between goals (see the module doc)."""

    def __init__(self, free: _Free, goals: Sequence[_Goal]):
        self.free = free
        corners = [free.start[None, :], free.reflex, *(g.corners for g in goals)]
        nodes = np.unique(np.concatenate(corners), axis=0)
        #: Few enough corners for the search; else straight lines, obstacles ignored.
        self.exact = len(nodes) <= MAX_CORNERS
        if not self.exact:
            nodes = free.start[None, :]
        self.nodes = nodes
        self.start = int(np.flatnonzero((nodes == free.start).all(axis=1))[0])
        n = len(nodes)
        i, j = np.triu_indices(n, k=1)
        seen = free.visible(nodes[i], nodes[j])
        i, j = i[seen], j[seen]
        length = np.full((n, n), np.inf)
        np.fill_diagonal(length, 0.0)
        gaps = np.linalg.norm(nodes[i] - nodes[j], axis=1)
        length[i, j] = length[j, i] = gaps
        self.geodesic = _all_pairs(length)
        self._near: dict[str, FloatArray] = {}

    def near(self, goal: _Goal) -> FloatArray:
        """(n,): each corner's straight, visible distance to the goal (0 inside it, inf when
        no point of it is in sight).  The nearest visible point of the goal is the foot of
        the corner on one of its edges, or one of its corners (a corner of the search)."""
        if goal.name in self._near:
            return self._near[goal.name]
        nodes = self.nodes
        inside = shapely.covers(
            goal.shape.buffer(TOLERANCE * self.free.scale), shapely.points(nodes)
        )
        found = np.where(np.asarray(inside, dtype=bool), 0.0, np.inf)
        if len(goal.edges):
            a = goal.edges[None, :, 0, :]
            d = goal.edges[None, :, 1, :] - a
            length2 = np.maximum(np.einsum("...j,...j->...", d, d), 1e-300)
            along = np.einsum("...j,...j->...", nodes[:, None, :] - a, d) / length2
            foot = a + np.clip(along, 0.0, 1.0)[..., None] * d
            gap = np.linalg.norm(nodes[:, None, :] - foot, axis=-1)
            k = foot.shape[1]
            ok = self.free.visible(np.repeat(nodes, k, axis=0), foot.reshape(-1, 2))
            if not self.exact:
                ok[:] = True  # straight lines: every point is in sight
            gap = np.where(ok.reshape(gap.shape), gap, np.inf)
            found = np.minimum(found, gap.min(axis=1))
        self._near[goal.name] = found
        return found

    def first(self, goal: _Goal) -> float:
        """The shortest path from the start into ``goal``: exact (to the tolerance)."""
        return float((self.geodesic[self.start] + self.near(goal)).min())

    def leg(self, origin: _Goal, goal: _Goal) -> float:
        """A lower bound on the shortest path from any point of ``origin`` into ``goal``:
        a path bending at a corner of the search, or one straight segment (no shorter than
        the distance between the two goals)."""
        direct = float(shapely.distance(origin.shape, goal.shape))
        if direct <= 0.0 or not self.exact:
            return direct
        leave = (self.near(origin)[:, None] + self.geodesic).min(axis=0)
        bent = float((leave + self.near(goal)).min())
        return min(bent, direct)

    def through(self, goals: Sequence[_Goal]) -> list[float]:
        """Lower bounds on the path from the start into goals[0], then goals[1], ...: one per
        prefix of ``goals`` (the first exact, each later one adds a :meth:`leg`)."""
        found = [self.first(goals[0])]
        for origin, goal in itertools.pairwise(goals):
            found.append(found[-1] + self.leg(origin, goal))
        return found


def _all_pairs(length: FloatArray) -> FloatArray:
    """Shortest path lengths between all nodes of a small graph (Dijkstra from each)."""
    n = len(length)
    out = np.full((n, n), np.inf)
    adjacency = [np.flatnonzero(np.isfinite(length[u])) for u in range(n)]
    for source in range(n):
        dist = out[source]
        dist[source] = 0.0
        queue = [(0.0, source)]
        while queue:
            d, u = heapq.heappop(queue)
            if d > dist[u]:
                continue
            for v in adjacency[u].tolist():
                nd = d + length[u, v]
                if nd < dist[v]:
                    dist[v] = nd
                    heapq.heappush(queue, (nd, v))
    return out


def deadline_proofs(mission: Mission, abstraction: Abstraction) -> tuple[DeadlineBound, ...]:
    """Every deadline of the mission's task that no trajectory can meet, with its proof (the
    :func:`deadline_bounds` that are proven)."""
    return tuple(b for b in deadline_bounds(mission, abstraction) if b.proven)


def deadline_bounds(mission: Mission, abstraction: Abstraction) -> tuple[DeadlineBound, ...]:
    """The lower bound on the time of every deadline of the task in the fragment (see the
    module doc), proven impossible or not; one per conjunct and kind of check, stopping at
    the first proof of a conjunct.

    ``abstraction`` must cover the robot's whole free space (the mesh built without margin):
    the proof speaks of every trajectory, not only of those keeping the margin.
    """
    formula = mission.formula
    conjuncts = list(formula.args) if isinstance(formula, And) else [formula]
    allowed = invariant_mask(abstraction, untimed_skeleton(formula))
    free = _Free(abstraction, allowed, mission.robot.start)
    speed = mission.robot.max_speed + mission.robot.disturbance
    convention = mission.options.boundary
    goals: dict[Formula, _Goal] = {}

    def goal(p: Formula) -> _Goal:
        if p not in goals:
            goals[p] = _goal(free, p, convention)
        return goals[p]

    deadlines: list[tuple[Formula, list[tuple[Formula, float | None]], float]] = []
    #: per deadline: the operator of each step's own window (the first: the deadline's)
    operators: list[list[str]] = []
    patrolled: list[Formula] = []
    periods: list[tuple[Formula, Formula, float, str]] = []
    for part in conjuncts:
        match part:
            case BoundedEventually(arg, interval) if interval.low == 0.0:
                steps = _chain_operators(arg)
                if steps is not None and math.isfinite(interval.high):
                    deadlines.append((part, [(g, w) for g, w, _ in steps], interval.high))
                    operators.append([to_text(part), *(o for _, _, o in steps[1:])])
            case Globally(BoundedEventually(arg, interval)) if (
                interval.low == 0.0 and is_propositional(arg)
            ):
                patrolled.append(arg)
                if math.isfinite(interval.high):
                    inner = to_text(BoundedEventually(arg, interval))
                    periods.append((part, arg, interval.high, inner))
                    deadlines.append((part, [(arg, None)], interval.high))
                    operators.append([inner])
            case Globally(Eventually(arg)) if is_propositional(arg):
                patrolled.append(arg)
            case _:
                pass
    for _, chain, _ in deadlines:
        for p, _ in chain:
            goal(p)
    for p in patrolled:
        goal(p)
    paths = _Paths(free, list(goals.values()))
    bounds: list[DeadlineBound] = []

    def bound(
        part: Formula, what: str, deadline: float, distance: float, operator: str = ""
    ) -> DeadlineBound:
        distance = max(0.0, distance - TOLERANCE * free.scale)
        return DeadlineBound(
            conjunct=to_text(part),
            what=what,
            deadline=deadline,
            earliest=distance / speed,
            distance=distance,
            speed=speed,
            span=part.span,
            anchor=to_text(part),
            operator=operator,
        )

    def keep(found: DeadlineBound | None) -> bool:
        """Record ``found``; True when it is a proof."""
        if found is not None:
            bounds.append(found)
        return found is not None and found.proven

    for (part, chain, deadline), own in zip(deadlines, operators, strict=True):
        reached = paths.through([goal(p) for p, _ in chain])
        total = deadline
        names: list[str] = []
        for index, (p, window) in enumerate(chain):
            if index > 0:
                if window is None:
                    break
                total += window
                gap = paths.leg(goal(chain[index - 1][0]), goal(p))
                what = f"going from {names[-1]} to {to_text(p)}"
                if keep(bound(part, what, window, gap, own[index])):
                    break
            names.append(to_text(p))
            what = "reaching " + ", then ".join(names) + " from the start"
            if keep(bound(part, what, total, reached[index], own[0] if index == 0 else "")):
                break
    single = [(part, chain[0][0], d) for part, chain, d in deadlines if len(chain) == 1]
    if 2 <= len(single) <= MAX_ORDERS_OF and not any(b.proven for b in bounds):
        keep(_every_order(single, paths, goal, bound))
    for part, p, period, inner in periods:
        for q in patrolled:
            if q != p:
                gap = paths.leg(goal(p), goal(q))
                what = f"a round trip from {to_text(p)} to {to_text(q)} and back"
                if keep(bound(part, what, period, 2 * gap, inner)):
                    break
    return tuple(bounds)


def _every_order(
    single: Sequence[tuple[Formula, Formula, float]],
    paths: _Paths,
    goal: Callable[[Formula], _Goal],
    bound: Callable[[Formula, str, float, float], DeadlineBound],
) -> DeadlineBound | None:
    """Deadlines from the start on several goals ``(conjunct, goal, deadline)``: the goals
    are first reached in some order; a proof when every order misses one of the deadlines
    (stated for the order that misses by the least)."""
    closest: tuple[float, DeadlineBound] | None = None
    for order in itertools.permutations(range(len(single))):
        reached = paths.through([goal(single[k][1]) for k in order])
        names = [to_text(single[k][1]) for k in order]
        missed: DeadlineBound | None = None
        for position, k in enumerate(order):
            what = "reaching " + ", then ".join(names[: position + 1]) + " from the start"
            found = bound(single[k][0], what, single[k][2], reached[position])
            if found.proven:
                missed = found
                break
        if missed is None:
            return None  # this order may meet every deadline
        lateness = missed.earliest - missed.deadline
        if closest is None or lateness < closest[0]:
            closest = (lateness, missed)
    assert closest is not None
    best = closest[1]
    whole = And(tuple(part for part, _, _ in single))
    return DeadlineBound(
        conjunct=to_text(whole),
        what=f"{best.what} (the order that comes closest; every order of first visits misses "
        f"a deadline)",
        deadline=best.deadline,
        earliest=best.earliest,
        distance=best.distance,
        speed=best.speed,
        span=single[0][0].span,
        anchor=to_text(single[0][0]),
    )
