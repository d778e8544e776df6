"""Planning for the shortest path (``options.cost: length``): plan, pull the string, re-weigh,
re-plan.

The planner weighs a move of the transition system by the segment between the midpoints of
the edges it crosses; the controllers follow the shortest path through the plan's channel of
triangles (:mod:`tlmpc.control.channel`, with its portal insets), which is shorter and
bends only where it must.  Which channel has the shortest such path is not a sum of
per-move weights known beforehand (a move's piece depends on the whole channel), so, as
for the ``time`` metric (:mod:`tlmpc.pipeline.mintime`), the planner iterates:

1. plan with every move weighing its midpoint length;
2. pull the string through the plan's channel (no controller is solved); the plan's
   **path length** is that path's length over the prefix plus ``beta`` times one lap of the
   cycle (a stay: to where the path enters its triangle);
3. every move the plan made now weighs its piece of that path (a move made twice: its last
   use; the cycle's from the middle lap); the other moves keep their midpoint lengths
   scaled by the first plan's path length over its cost (unscaled, every move made looks
   cheaper than any other and the first channel is planned again), and the plan is made
   again;
4. stop at a **fixed point** (the new plan is one already pulled), after
   :data:`MAX_REPLANS` re-plans, or before the plans' products would pass
   :data:`NODE_BUDGET` nodes.  The kept plan starts as the first; a re-plan replaces it
   when its path is more than :data:`MIN_GAIN` shorter *and* its exact time (the time metric's
   measure: controllers synthesised, trajectory simulated, prefix + ``beta`` x lap) is not
   longer (at most :data:`MAX_TIME_CHECKS` re-plans are simulated).  So the kept plan is
   never longer nor slower than the first.

Before the re-plans, an automaton with four acceptance sets or more is planned again awaiting
the sets in other orders (:func:`order_candidates`), and a plan touching a region and turning
back is made (:mod:`tlmpc.pipeline.touches`); each is kept on the re-plans' terms, by the
same check (:meth:`_Kept.offer`).  After them the kept plan is planned again on its mesh cut
into rings where its path bends round a corner (:mod:`tlmpc.pipeline.corners`), re-planned
there the same way (:class:`_Rounds`), and the shortest path pulled there is kept when its
**trajectory** is shorter, its path no longer and its exact time no longer than the midpoint
plan's (:meth:`_Kept.offer_trajectory`): the cut is for the fields to follow the path closer,
which the path's length does not see.  Last, the kept plan's visits are touched rather than
crossed where that is shorter (:func:`tlmpc.pipeline.touches.visit_touch_candidate`), re-planned
there and kept on the re-plans' terms.

Every round is deterministic (operations are counted, no clock is read).  What is promised
(docs/planning.md): the kept plan's path is never longer, and its trajectory never slower,
than the midpoint plan's; it is not a proof that no channel has a shorter path (the moves no
plan made keep estimates) nor that the kept one is the shortest of those pulled (a shorter
one may be slower, and a plan cut at its corners is judged by its trajectory).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from tlmpc.base.errors import TlmpcError
from tlmpc.mission.model import Mission
from tlmpc.pipeline.corners import Bends, corner_candidate, followed_path, plan_bends
from tlmpc.pipeline.touches import touch_candidate, visit_touch_candidate
from tlmpc.planning.mission import Planned, replan
from tlmpc.planning.product import START_SLOT, STUTTER_COST
from tlmpc.planning.timing import MoveKey, MoveTimes, move_key

#: A re-plan replaces the kept plan only when its path is shorter by more than this fraction:
#: the fields' speeds, which the path's length does not see, differ more than that between
#: channels (a bench room's re-plan 0.03 % shorter took 10 % longer).
MIN_GAIN = 0.002
#: At most this many re-plans are simulated to check that they are not slower (each costs a
#: controller synthesis and an exact simulation, as a round of the time metric does).
MAX_TIME_CHECKS = 2
#: At most this many re-plans after the first plan.
MAX_REPLANS = 6
#: At most this many re-plans on the mesh cut at the corners (:mod:`tlmpc.pipeline.corners`).
MAX_RING_REPLANS = 3
#: ... and none that would bring the products of all the plans made past this many nodes (a
#: re-plan costs about what the plan before it did, counted by its product's nodes: on a
#: large mesh the loop stops early or does not run at all, deterministically).
NODE_BUDGET = 250_000


@dataclass(frozen=True, slots=True)
class Pulled:
    """A plan's path length (prefix + beta x lap) and each move's piece of the path."""

    length: float
    moves: Mapping[MoveKey, float]


def plan_shortest(mission: Mission, planned: Planned) -> Planned:
    """``planned`` or a re-plan of it whose channel's shortest path is shorter (see the
    module doc); under other metrics, or when not even one re-plan fits the budget:
    ``planned`` as it is (without the statistics below).

    The witness's ``stats`` record ``path_length`` (the kept plan's), ``path_lengths``
    (each round's, in order), ``length_rounds``, ``length_fixed_point`` and
    ``length_time_checks`` (the exact times of the re-plans short enough to be simulated);
    where the acceptance sets were awaited in other orders (:func:`order_candidates`)
    ``order_lengths`` (each order's path length, the first plan's order first); and where a
    plan with U-turns gave a touch candidate (:mod:`tlmpc.pipeline.touches`)
    ``touch_length`` (its path length) and, when that was short enough to simulate,
    ``touch_time`` (its exact time); the ring and corridor candidates' ``ring_lengths``,
    ``ring_time``, ``corridor_lengths`` and ``corridor_time``; and where the kept plan's visits
    gave one (:func:`~tlmpc.pipeline.touches.visit_touch_candidate`) ``visit_lengths`` (its
    rounds' path lengths) and, when it was simulated, ``visit_time``.
    """
    spent = _nodes(planned)  # product nodes of the plans made so far
    if mission.options.cost != "length" or spent + spent > NODE_BUDGET:
        return planned  # (no re-plan would fit the budget: nothing to pull for)
    try:
        first = pull(mission, planned)
    except TlmpcError:  # the control stage will say what is wrong with the plan
        return planned
    kept = _Kept(mission, planned, first.length)
    checked: list[float] = []  # the exact times of the re-plans short enough to check
    history = [first.length]
    measured: dict[MoveKey, float] = dict(first.moves)
    seen = {planned.route()}
    # The moves no plan made keep their midpoint lengths scaled as the first plan's path
    # compares with its midpoint cost: unscaled, every measured move looks cheaper than
    # any other and the first channel is always planned again.
    cost = planned.witness.cost
    ratio = first.length / cost if cost > 0.0 and first.length > 0.0 else 1.0
    extra: dict[str, Any] = {}
    # The same lasso awaiting the acceptance sets in another order (its own budget, as the
    # touch candidate's below: the re-plans run as they would without it).  The shortest
    # path among the orders' plans is kept on the re-plans' terms.
    ordered = order_candidates(mission, planned)
    if ordered:
        lengths = [first.length]
        best_order: tuple[Planned, Pulled] | None = None
        for candidate in ordered:
            found_order = _pulled(mission, candidate)
            lengths.append(math.inf if found_order is None else found_order.length)
            if found_order is not None and (
                best_order is None or found_order.length < best_order[1].length
            ):
                best_order = (candidate, found_order)
            seen.add(candidate.route())
        extra["order_lengths"] = lengths
        if best_order is not None and kept.offer(*best_order, verified=True) is not None:
            measured.update(best_order[1].moves)
    # A plan that touches a region and turns back, on the mesh split where it touches
    # (tlmpc.pipeline.touches): a candidate like the re-plans, kept on the same terms, its
    # exact time checked apart from theirs.
    # (its own budget, the plan with U-turns and the re-plan on the split mesh: the re-plans
    # below run as they would without it)
    if 2 * _nodes(kept.planned) <= NODE_BUDGET:
        # on the midpoint lengths alone: the first plan's measured pieces would draw the plan
        # with U-turns back into the first plan's channel (Example 6 touched a core by its
        # far side edge, its exact time 39.0 s against 38.3 s so)
        touched = touch_candidate(mission, kept.planned, MoveTimes(speed=1.0))
        found_touch = None if touched is None else _pulled(mission, touched)
        if touched is not None and found_touch is not None:
            seen.add(touched.route())
            extra["touch_length"] = found_touch.length
            time = kept.offer(touched, found_touch, verified=True)
            if time is not None:
                extra["touch_time"] = time
            if kept.planned is touched:
                measured.update(found_touch.moves)
    # the re-plans go on from the kept plan, on its mesh
    rounds = _Rounds(mission, kept.planned, ratio, measured=measured, seen=seen, history=history)

    def check(following: Planned, found: Pulled) -> None:
        if len(checked) < MAX_TIME_CHECKS:
            time = kept.offer(following, found, verified=False)
            if time is not None:
                checked.append(time)

    spent = rounds.run(MAX_REPLANS, spent, check)
    # The kept plan planned again on its mesh cut into rings where its path bends round a
    # corner (tlmpc.pipeline.corners), and re-planned there as above: the shortest path
    # pulled on that mesh is kept when its trajectory is shorter.  First on the mesh as it
    # is, then, where the budget still allows, with the route's corridor meshed finer, each
    # judged against the plan kept so far.
    base_plan = kept.planned
    bends: Bends | None = None
    for refine in (False, True):
        if spent + 2 * _nodes(base_plan) > NODE_BUDGET:
            break
        if bends is None:
            bends = plan_bends(mission, base_plan)
            if bends is None:
                break  # its steps cannot be read (the control stage will say why)
        ringed = corner_candidate(mission, base_plan, bends, refine=refine)
        kind = "corridor" if refine else "ring"
        ring_best, spent = _candidate_rounds(mission, ringed, ratio, spent, extra, kind)
        if ring_best is not None:
            time = kept.offer_trajectory(*ring_best)
            if time is not None:
                extra[f"{kind}_time"] = time
    # The kept plan's visits touched rather than crossed (tlmpc.pipeline.touches): its mesh
    # split where its path would touch a label it visits, re-planned there as above, kept
    # on the re-plans' terms.  Its own budget, as the touch candidate's (what the rounds
    # above spent does not count: run last, it would otherwise rarely run at all).
    if 2 * _nodes(kept.planned) <= NODE_BUDGET:
        visiting = visit_touch_candidate(mission, kept.planned)
        own = _nodes(kept.planned)  # the nodes its budget has spent: the kept plan's
        visit_best, _ = _candidate_rounds(mission, visiting, ratio, own, extra, "visit")
        if visit_best is not None:
            time = kept.offer(*visit_best, verified=True)
            if time is not None:
                extra["visit_time"] = time
    best = kept.planned
    stats: dict[str, Any] = {
        **best.witness.stats,
        "path_length": kept.length,
        "path_lengths": history,
        "length_rounds": len(history),
        "length_fixed_point": rounds.fixed,
        "length_time_checks": checked,
        **extra,
    }
    return replace(best, witness=replace(best.witness, stats=stats))


def _candidate_rounds(
    mission: Mission,
    candidate: Planned | None,
    ratio: float,
    spent: int,
    extra: dict[str, Any],
    kind: str,
) -> tuple[tuple[Planned, Pulled] | None, int]:
    """A candidate on another mesh pulled and re-planned there (up to
    :data:`MAX_RING_REPLANS` rounds within the budget): its shortest plan and path (None
    when there is no candidate or its path cannot be pulled) and the nodes ``spent`` after
    it; its rounds' path lengths recorded in ``extra`` as ``{kind}_lengths``."""
    found = None if candidate is None else _pulled(mission, candidate)
    if candidate is None or found is None:
        return None, spent
    spent += _nodes(candidate)
    rounds = _Rounds(
        mission,
        candidate,
        ratio,
        measured=dict(found.moves),
        seen={candidate.route()},
        history=[found.length],
        best=(candidate, found),
    )
    spent = rounds.run(MAX_RING_REPLANS, spent)
    extra[f"{kind}_lengths"] = rounds.history
    return rounds.best, spent


class _Rounds:
    """Re-plans from a plan, every move a plan made weighing its piece of that plan's path
    (its last use), the others their midpoint lengths scaled by ``ratio``: the rounds of the
    module doc, shared by the re-plans on the mesh as built and on the mesh cut at corners."""

    def __init__(
        self,
        mission: Mission,
        planned: Planned,
        ratio: float,
        *,
        measured: dict[MoveKey, float],
        seen: set[Any],
        history: list[float],
        best: tuple[Planned, Pulled] | None = None,
    ) -> None:
        self.mission = mission
        self.current = planned
        self.ratio = ratio
        self.measured = measured
        self.seen = seen
        self.history = history
        #: the re-plan (or the given ``best``) whose path was the shortest
        self.best = best
        #: whether the rounds stopped at a plan already pulled
        self.fixed = False

    def run(
        self,
        limit: int,
        spent: int,
        each: Callable[[Planned, Pulled], None] | None = None,
    ) -> int:
        """Up to ``limit`` re-plans, none that would bring the nodes ``spent`` past
        :data:`NODE_BUDGET`, ``each`` called on every new one; the nodes spent after them."""
        for _ in range(limit):
            # a re-plan costs about what the last plan did: none that would pass the budget
            if spent + _nodes(self.current) > NODE_BUDGET:
                break
            spent += _nodes(self.current)
            weights = MoveTimes(speed=1.0 / self.ratio, measured=dict(self.measured))
            try:
                following = replan(self.mission, self.current, weights)
                found = pull(self.mission, following)
            except TlmpcError:
                break
            shape = following.route()
            if shape in self.seen:
                self.fixed = True
                break
            self.seen.add(shape)
            self.history.append(found.length)
            if each is not None:
                each(following, found)
            self.measured.update(found.moves)
            self.current = following
            if self.best is None or found.length < self.best[1].length:
                self.best = (following, found)
        return spent


class _Kept:
    """The kept plan, its path length and (once a candidate needed it) its exact time: the
    one place that decides whether a candidate replaces it."""

    def __init__(self, mission: Mission, planned: Planned, length: float) -> None:
        self.mission = mission
        self.planned = planned
        self.length = length
        self.time: float | None = None
        #: the kept plan's trajectory length (prefix + beta x lap), once measured
        self.travelled: float | None = None
        #: the midpoint plan (the first kept), its path length and exact time: a plan judged
        #: by its trajectory (:meth:`offer_trajectory`) keeps the promise against them
        self.first = planned
        self.first_length = length
        self.first_time: float | None = None

    def offer(self, candidate: Planned, pulled: Pulled, *, verified: bool) -> float | None:
        """Keep ``candidate`` when its path is more than :data:`MIN_GAIN` shorter **and** its
        trajectory is not slower (the length does not see the fields' speeds): both are then
        simulated, as the time metric measures a plan; ``verified`` also asks its trace to
        satisfy the task (a plan on another mesh or automaton).  The candidate's exact time
        when it was simulated, else None."""
        if not pulled.length < self.length * (1.0 - MIN_GAIN):
            return None
        self._measure_kept()
        assert self.time is not None
        time, travelled = _run(self.mission, candidate, verified=verified)
        if time <= self.time:
            self._keep(candidate, pulled.length, time, travelled)
        return time

    def offer_trajectory(self, candidate: Planned, pulled: Pulled) -> float | None:
        """Keep ``candidate`` (a plan on another mesh: its trace must satisfy the task) when
        its **trajectory** is more than :data:`MIN_GAIN` shorter than the kept plan's, its path
        is not longer and its exact time not longer than the midpoint plan's (so the kept
        plan keeps the promise of the module doc).  A plan on a mesh cut at the corners
        follows its path more closely than the plans before, whose path may be as short:
        the trajectory is what its cut was for.  The candidate's exact time when it was
        simulated, else None."""
        if not pulled.length <= self.first_length:
            return None
        self._measure_kept()
        assert self.first_time is not None
        assert self.travelled is not None
        time, travelled = _run(self.mission, candidate, verified=True)
        if time <= self.first_time and travelled < self.travelled * (1.0 - MIN_GAIN):
            self._keep(candidate, pulled.length, time, travelled)
        return time

    def _measure_kept(self) -> None:
        """Simulate the kept plan once (the first time it is simulated it is the midpoint
        plan: a candidate replaces it only after this)."""
        if self.time is None:
            self.time, self.travelled = _run(self.mission, self.planned, verified=False)
            if self.planned is self.first:
                self.first_time = self.time

    def _keep(self, candidate: Planned, length: float, time: float, travelled: float) -> None:
        self.planned, self.length, self.time, self.travelled = (
            candidate,
            length,
            time,
            travelled,
        )


def order_candidates(mission: Mission, planned: Planned) -> list[Planned]:
    """``planned``'s task planned again (its mesh, the moves weighing their midpoint lengths)
    awaiting the automaton's acceptance sets in other orders
    (:func:`tlmpc.automata.degeneralize.acceptance_orders`): a minimum-cost lasso of one
    degeneralization visits the sets in its order once a lap, another order only in two laps
    or more, so a patrol of four goals listed round a square's diagonals would otherwise be
    planned along them.  Every other order when there are at most :data:`MAX_ORDER_PLANS`
    and all their plans fit :data:`NODE_BUDGET` product nodes; else the one order of the
    shortest tour between the sets' triangles (:func:`tour_order`), when it is another and
    one more plan fits.  None when the automaton has fewer than four sets (one order up to
    direction)."""
    from tlmpc.automata.degeneralize import acceptance_orders, reorder_acceptance

    automaton = planned.automaton
    count = automaton.num_acc
    if count < 4:
        return []
    orders = math.factorial(count - 1) // 2 - 1  # besides the first plan's
    if orders <= MAX_ORDER_PLANS and (orders + 1) * _nodes(planned) <= NODE_BUDGET:
        chosen = list(itertools.islice(acceptance_orders(count), 1, None))
    elif 2 * _nodes(planned) <= NODE_BUDGET:
        best = tour_order(planned)
        chosen = [] if best is None or best == tuple(range(count)) else [best]
    else:
        return []
    found = []
    for order in chosen:
        reordered = replace(planned, automaton=reorder_acceptance(automaton, order))
        try:
            found.append(replan(mission, reordered, MoveTimes(speed=1.0)))
        except TlmpcError:
            continue
    return found


#: Every other order is planned for at most this many (the 11 others of five sets): beyond,
#: one plan costs more than its nodes say (sixty plans of a 4,004-node product tripled a
#: six-room patrol's plan stage), and the tour order is planned alone.
MAX_ORDER_PLANS = 11

#: :func:`tour_order` compares the orders of at most this many acceptance sets (2,520 orders).
MAX_TOUR_SETS = 8


def tour_order(planned: Planned) -> tuple[int, ...] | None:
    """The order of the automaton's acceptance sets (one of
    :func:`~tlmpc.automata.degeneralize.acceptance_orders`, the first of equals) whose closed
    tour is shortest, a set standing for the triangles whose letter takes an edge it marks
    and the distance between two sets the shortest walk between their triangles from
    centroid to centroid (one multi-source search per set); None past
    :data:`MAX_TOUR_SETS` sets."""
    from tlmpc.automata.degeneralize import acceptance_orders
    from tlmpc.automata.guards import guard_holds
    from tlmpc.planning.search import Graph, distances

    automaton, mesh = planned.automaton, planned.abstraction
    count = automaton.num_acc
    if count > MAX_TOUR_SETS:
        return None
    letters = mesh.letters
    members: list[set[int]] = [set() for _ in range(count)]  # letters taking a marked edge
    for edge in automaton.edges:
        if not edge.marks:
            continue
        taking = [i for i, letter in enumerate(letters) if guard_holds(edge.guard, letter)]
        for mark in edge.marks:
            members[mark].update(taking)
    # the mesh's dual graph, two triangles joined by the distance between their centroids
    centroids = mesh.vertices[mesh.triangles].mean(axis=1)
    rows, sides = np.nonzero(mesh.neighbors >= 0)
    columns = mesh.neighbors[rows, sides].astype(np.int64)
    weights = np.hypot(*(centroids[rows] - centroids[columns]).T)
    graph, _ = Graph.from_edges(rows.astype(np.int64), columns, weights, mesh.num_triangles)
    letter_of = mesh.letter_of
    distance = np.zeros((count, count))
    for mark in range(count):
        sources = np.flatnonzero(np.isin(letter_of, sorted(members[mark])))
        if len(sources) == 0:
            return None
        reach = distances(graph, sources)
        for other in range(count):
            targets = np.isin(letter_of, sorted(members[other]))
            distance[mark, other] = float(reach[targets].min())
    best: tuple[float, tuple[int, ...]] | None = None
    for order in acceptance_orders(count):
        length = sum(distance[order[i], order[(i + 1) % count]] for i in range(count))
        if best is None or length < best[0]:
            best = (length, order)
    return None if best is None else best[1]


def _pulled(mission: Mission, planned: Planned) -> Pulled | None:
    try:
        return pull(mission, planned)
    except TlmpcError:
        return None


def _run(mission: Mission, planned: Planned, *, verified: bool) -> tuple[float, float]:
    """The plan's exact time and its trajectory's length over the same span
    (:func:`tlmpc.pipeline.mintime.measure`: prefix + beta x lap of its simulated trajectory,
    sampled at least every :data:`LENGTH_SAMPLES` th of the mesh's extent); both inf when its
    controllers or simulation fail or (``verified``) its trace does not satisfy the task
    (the self-check's verifier: a plan on a split mesh is checked before it can replace one
    made on the mesh as built)."""
    from tlmpc.pipeline.mintime import simulated, step_times
    from tlmpc.simulate import trace_to_json
    from tlmpc.verify import verdict_to_json, verify_document

    vertices = planned.abstraction.vertices
    extent = float(np.hypot(*(vertices.max(axis=0) - vertices.min(axis=0))))
    gap = extent / LENGTH_SAMPLES / mission.robot.max_speed
    try:
        controllers, trace = simulated(mission, planned, max_gap=gap)
    except TlmpcError:
        return math.inf, math.inf
    if verified:
        verdict = verdict_to_json(verify_document(dict(trace_to_json(trace, mission))))
        if not verdict["satisfied"]:
            return math.inf, math.inf
    found = step_times(planned.abstraction, controllers, trace, planned.witness.beta)
    return found.exact_time, found.exact_length


#: The samples a plan's trajectory is measured by are at most this fraction of the mesh's
#: extent apart (at max_speed): a polyline through them is then within a few parts in ten
#: thousand of the flow's length round the corners' small triangles.
LENGTH_SAMPLES = 200


def _nodes(planned: Planned) -> int:
    """The product nodes the plan's search held (built, or reached on demand)."""
    stats = planned.witness.stats
    return int(stats.get("product_nodes") or stats.get("product_reached") or 0)


def pull(mission: Mission, planned: Planned) -> Pulled:
    """The shortest path through ``planned``'s channel as the controllers follow it
    (:func:`tlmpc.control.follow.path_guides`): its length (see the module doc) and the
    length of each of D's moves on it, keyed by :func:`~tlmpc.planning.timing.move_key`
    (plus the weights' stutter cost)."""
    from tlmpc.control.synthesize import plan_steps

    abstraction, witness = planned.abstraction, planned.witness
    steps, loop_start = plan_steps(abstraction, witness)
    pieces = followed_path(mission, planned, steps, loop_start)
    lengths = [0.0 if p is None else math.dist(p.entry, p.exit) for p in pieces]
    neighbors = abstraction.neighbors
    moves: dict[MoveKey, float] = {}
    prefix = 0.0
    lap = 0.0
    for index, step in enumerate(steps):
        if step.exit_edge is None and step.through is None:
            break  # the stay: the plan's cost ends where its triangle is entered
        if loop_start is None or index < loop_start:
            prefix += lengths[index]
        else:
            lap += lengths[index]
        if step.through is not None or step.exit_edge is None:
            continue
        # the edge the piece entered by: the step before's (the cycle's first step: the
        # wrap's, its piece being the middle lap's)
        before = index - 1 if index > 0 else None
        if loop_start is not None and index == loop_start:
            before = len(steps) - 1
        if before is None:
            slot = START_SLOT
        elif steps[before].through is not None:
            continue  # entered at a vertex: not one of D's moves
        else:
            sides = neighbors[step.triangle].tolist()
            if steps[before].triangle not in sides:
                continue
            slot = sides.index(steps[before].triangle)
        key = move_key(abstraction, step.triangle, slot, step.exit_edge)
        moves[key] = lengths[index] + STUTTER_COST
    return Pulled(length=prefix + witness.beta * lap, moves=moves)
