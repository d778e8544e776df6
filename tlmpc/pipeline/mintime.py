"""Planning for minimum time (``options.cost: time``): plan, simulate exactly, re-weigh, re-plan.

The time a plan step takes depends on its controller and on where the robot enters the
triangle, and both exist only once the whole plan is known (the controllers of consecutive
steps share their vertex velocities).  So the minimum-time plan is found by iterating:

1. plan with every move weighing its estimate (its length at top speed,
   :mod:`tlmpc.planning.timing`);
2. synthesise the plan's controllers and simulate its trajectory exactly (the control and
   simulate stages' own code); the plan's **exact time** is the time its trajectory needs for
   the prefix plus ``beta`` times one lap of the cycle (the second simulated lap, entered from
   the end of the first; a stay: the time to enter its triangle);
3. every move the plan used now weighs the time its step took on that trajectory (a move
   used twice: its last use; the cycle's from the second lap); the other moves keep their
   weights, and the plan is made again;
4. stop at a **fixed point** (the new plan is one already simulated, or the plan's exact
   time equals its planned cost: every weight on it is measured where it was used) or after
   :data:`MAX_REPLANS` re-plans, and keep the plan of least exact time (the first on ties)
   among those whose trajectory meets the task's time bounds (the dense-time verifier's
   verdict), or among all when none does.

Every round is deterministic, so the result is the same bytes on any machine.  What is
promised is stated in docs/planning.md: the kept plan is the fastest of those simulated (that
meet the time bounds, when one does), and
at a fixed point no plan is cheaper under the weights (exact times of the moves where the
simulated plans used them, estimates elsewhere).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import TlmpcError
from tlmpc.control.model import Controllers, StepController
from tlmpc.ltl.ast import bounded_operators
from tlmpc.mission.model import Mission
from tlmpc.planning.mission import Planned, plan_mission, replan
from tlmpc.planning.product import START_SLOT
from tlmpc.planning.timing import MoveKey, MoveTimes, move_key
from tlmpc.simulate.exact import Trace

#: At most this many re-plans after the first plan (each costs a plan, a controller
#: synthesis and an exact simulation).
MAX_REPLANS = 8
#: A plan's exact time "equals" its planned cost within this fraction of it (rounding).
FIXED_POINT_TOLERANCE = 1e-9


@dataclass(frozen=True, slots=True)
class Measured:
    """A plan's exact time and the simulated time of each move it used; whether its
    trajectory meets the task's time bounds (True for a task without any)."""

    exact_time: float
    moves: Mapping[MoveKey, float]
    meets_bounds: bool = True
    #: The trajectory's length over the same span (prefix + beta x lap), along its samples.
    exact_length: float = 0.0


def plan_minimum_time(
    mission: Mission,
    abstraction: Abstraction,
    automaton: Automaton,
    shortest: Callable[[Mission, Planned], Planned] | None = None,
) -> Planned:
    """The plan of ``mission`` (as :func:`~tlmpc.planning.mission.plan_mission`) of least
    exact time among the rounds of the module doc, preferring those whose trajectory meets
    the task's time bounds; other metrics: the plan as it is.

    ``shortest`` (the compile passes :func:`tlmpc.pipeline.shortest.plan_shortest`) turns the
    first plan into the ``length`` metric's kept plan before the rounds start: the first plan
    simulated is then the one ``options.cost: length`` compiles, and the kept plan is never
    slower than it.

    The witness's ``stats`` record ``exact_time`` (seconds), ``time_rounds`` (plans
    simulated), ``time_fixed_point``, ``exact_times`` (each round's, in order) and, for a
    task with time bounds, ``bounds_met`` (each round's).
    """
    if mission.options.cost != "time":
        return plan_mission(mission, abstraction, automaton)
    if shortest is None:
        first = plan_mission(mission, abstraction, automaton)
    else:
        # the length metric's own first plan (the time metric's weighs the same lengths over
        # max_speed, whose rounding can break a tie the other way), then its kept plan
        as_length = replace(mission, options=replace(mission.options, cost="length"))
        first = shortest(as_length, plan_mission(as_length, abstraction, automaton))
    speed = mission.robot.max_speed
    measured: dict[MoveKey, float] = {}
    history: list[float] = []
    met: list[bool] = []
    seen = {first.route()}
    best: tuple[tuple[bool, float], Planned] | None = None
    current = first
    fixed = False
    for round_index in range(MAX_REPLANS + 1):
        try:
            found = measure(mission, current)
        except TlmpcError:
            # the control or simulate stage will say why (for the first plan), or the
            # re-plan is not realised: the best plan so far stands
            break
        history.append(found.exact_time)
        met.append(found.meets_bounds)
        # a plan that meets the time bounds first, then the faster
        key = (not found.meets_bounds, found.exact_time)
        if best is None or key < best[0]:
            best = (key, current)
        cost = current.witness.cost
        if abs(found.exact_time - cost) <= FIXED_POINT_TOLERANCE * max(found.exact_time, 1.0):
            fixed = True
            break
        if round_index == MAX_REPLANS:
            break
        measured.update(found.moves)
        try:
            following = replan(mission, current, MoveTimes(speed=speed, measured=dict(measured)))
        except TlmpcError:
            break
        shape = following.route()
        if shape in seen:
            fixed = True
            break
        seen.add(shape)
        current = following
    if best is None:  # (the first plan is the length metric's: the compile's metric is time)
        return replace(first, witness=replace(first.witness, metric="time"))
    (_, exact), chosen = best
    stats: dict[str, Any] = {
        **chosen.witness.stats,
        "exact_time": exact,
        "time_rounds": len(history),
        "time_fixed_point": fixed,
        "exact_times": history,
        **({"bounds_met": met} if bounded_operators(mission.formula) else {}),
    }
    return replace(chosen, witness=replace(chosen.witness, metric="time", stats=stats))


def simulated(
    mission: Mission, planned: Planned, *, max_gap: float | None = None
) -> tuple[Controllers, Trace]:
    """``planned``'s controllers, synthesised, and their exact trajectory (samples at most
    ``max_gap`` apart in time when given: :func:`tlmpc.simulate.simulate`)."""
    from tlmpc.control import synthesize
    from tlmpc.simulate import simulate

    controllers = synthesize(
        planned.abstraction,
        planned.witness,
        mission.robot,
        source=mission.source,
        relevant=mission.formula.props(),
    )
    return controllers, simulate(planned.abstraction, controllers, mission, max_gap=max_gap)


def measure(mission: Mission, planned: Planned) -> Measured:
    """Synthesise ``planned``'s controllers, simulate them exactly and time every step."""
    controllers, trace = simulated(mission, planned)
    found = step_times(planned.abstraction, controllers, trace, planned.witness.beta)
    if not bounded_operators(mission.formula):
        return found
    from tlmpc.simulate import trace_to_json
    from tlmpc.verify.trace_input import from_document
    from tlmpc.verify.verdict import bound_slacks

    outcome, _ = bound_slacks(from_document(trace_to_json(trace, mission)))
    return replace(found, meets_bounds=outcome == "satisfied")


def step_times(
    abstraction: Abstraction, controllers: Controllers, trace: Trace, beta: float
) -> Measured:
    """The exact time of the run ``trace`` of ``controllers`` (see the module doc), the
    trajectory's length over the same span (along the samples) and the time of each move of
    D it made, keyed by :func:`~tlmpc.planning.timing.move_key`.

    The simulator runs the steps in order and then the cycle once more; every step but a
    stay ends at a crossing sample (``trace.crossings``, one per such step in that order).
    """
    steps = controllers.steps
    order = list(range(len(steps)))
    loop = controllers.loop_start
    if loop is not None:
        order += order[loop:]
    moving = [p for p, k in enumerate(order) if not steps[k].is_stay]
    exit_time = {p: float(trace.times[trace.crossings[n]]) for n, p in enumerate(moving)}
    moves: dict[MoveKey, float] = {}
    previous_end = 0.0
    for position, index in enumerate(order):
        step = steps[index]
        if step.is_stay:
            break
        end = exit_time[position]
        slot = _entry_slot(abstraction, order, steps, position)
        if slot is not None and step.exit_edge is not None:
            moves[move_key(abstraction, step.triangle, slot, step.exit_edge)] = end - previous_end
        previous_end = end
    first_pass = len(steps)
    travelled = np.concatenate(
        [[0.0], np.cumsum(np.hypot(*np.diff(np.asarray(trace.points), axis=0).T))]
    )
    exit_length = {n: float(travelled[trace.crossings[k]]) for k, n in enumerate(moving)}
    if loop is None:
        last = max(moving, default=None)
        arrived = 0.0 if last is None else exit_time[last]
        length = 0.0 if last is None else exit_length[last]
        return Measured(exact_time=arrived, moves=moves, exact_length=length)
    prefix_time = exit_time[loop - 1] if loop > 0 else 0.0
    prefix_length = exit_length[loop - 1] if loop > 0 else 0.0
    lap = exit_time[len(order) - 1] - exit_time[first_pass - 1]
    lap_length = exit_length[len(order) - 1] - exit_length[first_pass - 1]
    return Measured(
        exact_time=prefix_time + beta * lap,
        moves=moves,
        exact_length=prefix_length + beta * lap_length,
    )


def _entry_slot(
    abstraction: Abstraction,
    order: list[int],
    steps: tuple[StepController, ...],
    position: int,
) -> int | None:
    """The edge of the step's triangle the robot entered it by (the start slot for the first
    step); None next to a vertex passage (the move is not one of D's)."""
    step = steps[order[position]]
    if step.is_vertex:
        return None
    if position == 0:
        return START_SLOT
    before = steps[order[position - 1]]
    if before.is_vertex:
        return None
    sides = abstraction.neighbors[step.triangle].tolist()
    return sides.index(before.triangle) if before.triangle in sides else None
