"""Time bounds in ``tlmpc compile``: the compiled trajectory is checked against every bound.

The planner plans a bounded task on its untimed skeleton (:func:`tlmpc.ltl.bounds.untimed_skeleton`)
and the controllers run at up to ``max_speed``; whether the exact trajectory then meets the
task's deadlines, durations and periods is decided here by the dense-time verifier, and each
bound's slack (seconds, signed) goes into ``summary.json``.  When the trajectory misses a
bound, compile fails with one of two answers:

* **P050**, a proof (exit 1): a deadline no trajectory of the robot can meet, with the
  earliest time the task's goals can be reached (:mod:`tlmpc.planning.deadlines`);
* **P051**, no proof (exit 4, inconclusive): the plan found misses a bound, and none of the
  task's deadlines is proven impossible: another plan might meet it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from tlmpc.abstraction.model import Abstraction
from tlmpc.base.errors import EXIT_INCONCLUSIVE, Diagnostic, NoPlanError, TlmpcError
from tlmpc.control.model import Controllers
from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedUntil,
    Equiv,
    Formula,
    Implies,
    Not,
    bounded_operators,
)
from tlmpc.ltl.printer import to_text
from tlmpc.mission.body import body_radius
from tlmpc.mission.model import Mission
from tlmpc.planning.deadlines import DeadlineBound
from tlmpc.verify.verdict import BoundSlack, bound_slacks

#: At most this many lower bounds are quoted in a P051 message.
MAX_SHOWN = 3


class DeadlineMissedError(TlmpcError):
    """The plan found misses a time bound and no proof says that every plan must (exit 4)."""

    exit_code = EXIT_INCONCLUSIVE


def _seconds(value: float | None) -> float | str | None:
    """A slack for JSON: a number, ``"inf"``/``"-inf"``, or None (no direction)."""
    if value is None or math.isfinite(value):
        return value
    return "inf" if value > 0 else "-inf"


def check_time_bounds(
    mission: Mission, trace: Mapping[str, Any], abstraction: Abstraction
) -> dict[str, Any] | None:
    """The slack of every time bound of the task on the compiled ``trace`` (None: the task
    has none); raises P050 or P051 when the trace does not satisfy the task.

    ``abstraction`` is the mesh the plan used; the proof is computed on the mesh without
    margin when the mission asks for one (it must speak of every trajectory).
    """
    if not bounded_operators(mission.formula):
        return None
    from tlmpc.verify.trace_input import from_document

    outcome, slacks = bound_slacks(
        from_document(dict(trace)), deadlines=_positive_deadlines(mission.formula)
    )
    bounds = _bounds(mission, abstraction)
    if outcome == "satisfied":
        return {"bounds": bound_report(mission.formula, slacks, bounds)}
    proofs = [b for b in bounds if b.proven]
    if proofs:
        raise NoPlanError(
            [
                Diagnostic(
                    code="P050",
                    message=p.message,
                    hint="a later deadline, a faster robot (robot.max_speed) or goals closer "
                    "to the start; the shortest path is measured in the free space the "
                    "task's invariants leave",
                    file=mission.source,
                    line=where[0],
                    col=where[1],
                )
                for p in proofs
                for where in [_position(mission, p)]
            ]
        )
    where = _first_missed(mission, slacks)
    raise DeadlineMissedError(
        Diagnostic(
            code="P051",
            message="no plan was found that meets the task's time bounds (none is proven "
            f"impossible): the {_planned(mission)} plan of the untimed task misses "
            + _missed(slacks)
            + _earliest(bounds),
            hint=_why_no_plan(mission)
            + ": deadlines between the earliest possible time and the plan's are not "
            "decided. Looser bounds, a faster robot or a task that fixes the order of the "
            "goals may help",
            file=mission.source,
            line=where[0],
            col=where[1],
        )
    )


def _planned(mission: Mission) -> str:
    """What the plan minimised, in words."""
    return {"time": "minimum-time", "length": "shortest", "hops": "fewest-moves"}.get(
        mission.options.cost, "minimum-cost"
    )


def _why_no_plan(mission: Mission) -> str:
    """Why a plan can miss a deadline that some trajectory meets."""
    if mission.options.cost == "time":
        return (
            "the plan minimises the exact time of the whole run (not the time to each goal), "
            "and its controllers do not drive the shortest path at full speed"
        )
    return (
        f"the plan minimises {'path length' if mission.options.cost == 'length' else 'moves'}"
        ", not time (options.cost: time plans for it), and its controllers do not drive the "
        "shortest path at full speed"
    )


def bound_report(
    formula: Formula, slacks: Sequence[BoundSlack], bounds: Sequence[DeadlineBound]
) -> list[dict[str, Any]]:
    """``summary.json``'s ``bounds``: per bounded operator of ``formula`` (pre-order) its
    ``slack``; for a deadline (``F[0,T]``, ``U[0,T]`` occurring positively) the plan's
    exact ``time`` for it (the tightest deadline the trajectory meets: ``T - slack``, as the
    verifier found it when it was asked, see :func:`bound_slacks`); and
    where the proof search bounds that operator's own window, its ``lower_bound`` (the
    earliest any trajectory can do it, seconds).  None where a number has no meaning."""
    deadlines = _positive_deadlines(formula)
    earliest: dict[str, float] = {}
    for proof in bounds:
        if proof.operator:
            earliest[proof.operator] = max(earliest.get(proof.operator, 0.0), proof.earliest)
    report: list[dict[str, Any]] = []
    for index, found in enumerate(slacks):
        high = deadlines.get(index)
        time = None
        if high is not None and found.time is not None:
            time = found.time
        elif high is not None and found.slack is not None and math.isfinite(found.slack):
            time = high - found.slack
        report.append(
            {
                "bound": found.bound,
                "slack": _seconds(found.slack),
                "time": time,
                "lower_bound": earliest.get(found.bound),
            }
        )
    return report


def _positive_deadlines(formula: Formula) -> dict[int, float]:
    """The deadline ``T`` of each ``F[0,T]``/``U[0,T]`` (finite ``T``) that occurs only
    positively, by its index among the formula's bounded operators (pre-order)."""
    index_of = {id(node): k for k, node in enumerate(bounded_operators(formula))}
    found: dict[int, float] = {}
    stack: list[tuple[Formula, bool | None]] = [(formula, True)]
    while stack:
        node, positive = stack.pop()
        if isinstance(node, BoundedEventually | BoundedUntil) and positive:
            interval = node.interval
            if interval.low == 0.0 and math.isfinite(interval.high):
                found[index_of[id(node)]] = interval.high
        if isinstance(node, Not):
            stack.append((node.arg, None if positive is None else not positive))
        elif isinstance(node, Implies):
            stack.append((node.left, None if positive is None else not positive))
            stack.append((node.right, positive))
        elif isinstance(node, Equiv):
            stack.extend((child, None) for child in node.children())
        else:
            stack.extend((child, positive) for child in node.children())
    return found


def _missed(slacks: tuple[BoundSlack, ...]) -> str:
    """The failing bounds in words (``F[0,30] dock by 3.2 s``): those that a finite loosening
    of their own would fix; else those that no loosening of their own fixes."""
    finite = [s for s in slacks if s.slack is not None and -math.inf < s.slack < 0]
    if finite:
        return ", ".join(f"`{s.bound}` by {-(s.slack or 0.0):.4g} s" for s in finite)
    hopeless = [s for s in slacks if s.slack == -math.inf]
    if hopeless:
        return ", ".join(f"`{s.bound}`" for s in hopeless) + " (no loosening of one bound helps)"
    return "the task (its bounds together)"


def _earliest(bounds: Sequence[DeadlineBound]) -> str:
    """What the proofs found short of a proof: the earliest times, against the deadlines."""
    if not bounds:
        return ""
    shown = [
        f"{b.what} takes at least {b.earliest:.4g} s (bound {b.deadline:.4g} s)"
        for b in bounds[:MAX_SHOWN]
    ]
    return "; the earliest any trajectory can do it: " + ", ".join(shown)


def _first_missed(
    mission: Mission, slacks: tuple[BoundSlack, ...]
) -> tuple[int | None, int | None]:
    """Where the first bound the plan misses was written (None, None: not known)."""
    for found in slacks:
        if found.slack is not None and found.slack < 0:
            return _located(mission, found.bound)
    return None, None


def _located(mission: Mission, text: str) -> tuple[int | None, int | None]:
    """The task part whose formula holds the operator printed as ``text``."""
    from tlmpc.mission.parts import task_parts

    for part in task_parts(mission):
        if any(to_text(node) == text for node in part.formula.walk()):
            return part.line, part.col
    return None, None


def _position(mission: Mission, proof: DeadlineBound) -> tuple[int | None, int | None]:
    """Where the proof's conjunct was written: its own position in ``ltl``, else the task
    phrase it comes from."""
    if proof.span is not None:
        return proof.span.line, proof.span.col
    from tlmpc.mission.parts import task_parts

    for part in task_parts(mission):
        formula = part.formula
        conjuncts = formula.args if isinstance(formula, And) else (formula,)
        if proof.anchor in {to_text(c) for c in conjuncts}:
            return part.line, part.col
    return None, None


def _bounds(mission: Mission, abstraction: Abstraction) -> tuple[DeadlineBound, ...]:
    from tlmpc.abstraction.layout import deepens_goals
    from tlmpc.mission.body import requested_margin
    from tlmpc.planning.deadlines import deadline_bounds
    from tlmpc.planning.mission import abstraction_for

    # the proof speaks of every trajectory: the regions as they are (not the goals' cores the
    # planner aims for) in the whole free space (not the part that keeps the margin), and
    # every position the body allows (not only those the planner's erosion keeps)
    exact = (
        body_radius(mission.robot) <= 0.0
        and requested_margin(mission) <= 0.0
        and not deepens_goals(mission)
    )
    mesh = abstraction if exact else abstraction_for(proof_mission(mission), 0.0, deep=False)
    return deadline_bounds(mission, mesh)


def disturbed_bounds(mission: Mission, controllers: Controllers) -> Diagnostic:
    """R009: the task's time bounds were checked on the undisturbed trajectory, and a push of
    up to ``robot.disturbance`` may delay it past them: the controllers guarantee that every
    step is left (within its exit-time bound), not when the undisturbed run leaves it."""
    steps = controllers.steps
    first_pass = steps if controllers.loop_start is None else steps[: controllers.loop_start]
    guaranteed = sum(
        s.exit_time_bound for s in first_pass if not s.is_stay and math.isfinite(s.exit_time_bound)
    )
    return Diagnostic(
        code="R009",
        severity="warning",
        message="the task's time bounds hold on the undisturbed trajectory; a push of up to "
        f"robot.disturbance {mission.robot.disturbance:g} may delay it past them (the "
        "controllers guarantee each step's exit, within its exit-time bound: the plan's "
        f"{'prefix' if controllers.loop_start is not None else 'steps'} within "
        f"{guaranteed:.4g} s at the latest, not the undisturbed times)",
        hint="leave the bounds slack for the push, and check runs under it with `tlmpc "
        "simulate OUT --model-disturbance adversarial`",
        file=mission.source,
        path="$.robot.disturbance",
    )


def proof_mission(mission: Mission) -> Mission:
    """``mission`` with the body the proofs plan with: one whose free space holds every
    position the true body allows.

    The planner erodes the free space conservatively (obstacle corners by a polygon outside
    the body's circle, reaching 1 / cos(pi / 32) of the distance, plus two steps of the
    snapping grid), so its mesh misses a sliver of the configuration space and a path bending
    round a corner there is shorter than any on the mesh: a 'proven' earliest time came out
    0.04 % above the true one.  The body is shrunk until that erosion, and two more grid steps
    for snapping inward, reach no further than the true radius."""
    from tlmpc.mission.cspace import QUAD_SEGS
    from tlmpc.mission.grid import grid_size

    radius = body_radius(mission.robot)
    if radius <= 0.0:
        return mission
    reach = math.cos(math.pi / (4 * QUAD_SEGS)) * (1.0 - 1e-9)
    smaller = max(0.0, radius * reach - 4.0 * grid_size(mission))
    robot = replace(mission.robot, radius=smaller, footprint=None, model="point", offset=0.0)
    return replace(mission, robot=robot, workspace=replace(mission.workspace, map_tolerance=0.0))
