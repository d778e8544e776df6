"""Per-conjunct progress and every violation, read off the evaluated pieces."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from tlmpc.ltl.ast import (
    BoundedEventually,
    BoundedGlobally,
    Eventually,
    Formula,
    Globally,
    Implies,
    Not,
    Or,
    Prop,
    Until,
)
from tlmpc.ltl.printer import to_text
from tlmpc.verify.clock import Clock, seconds
from tlmpc.verify.evaluate import Value
from tlmpc.verify.model import ConjunctReport, Outcome, Violation

BoolArray = npt.NDArray[np.bool_]
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Timeline:
    """The pieces in time: when each starts and ends (seconds from the log's first sample),
    where it is, what it is labelled."""

    starts: FloatArray
    ends: FloatArray
    positions: FloatArray
    labels: BoolArray
    names: list[str]
    clock: Clock  # the log's stamps of these times, and how they are written
    #: the names that are sensors or actions, not regions (a reactive run's)
    signals: frozenset[str] = frozenset()

    @property
    def size(self) -> int:
        """Number of pieces."""
        return len(self.starts)


def runs(mask: BoolArray) -> list[tuple[int, int]]:
    """Maximal runs ``[first, last]`` of True in ``mask``."""
    padded = np.concatenate([[False], mask, [False]]).astype(np.int8)
    edges = np.diff(padded)
    firsts = np.flatnonzero(edges == 1)
    lasts = np.flatnonzero(edges == -1) - 1
    return list(zip(firsts.tolist(), lasts.tolist(), strict=True))


def _at(line: Timeline, k: int) -> tuple[float, tuple[float, float]]:
    """When piece ``k`` starts (from the first sample) and where the robot is then.

    An open stretch carries its midpoint as position (that point labels it), but it starts
    at the instant of the piece before it (a sample or a crossing, under the closed
    convention): the robot is at that instant's position when the stretch begins."""
    first = k
    while first > 0 and line.starts[first - 1] == line.starts[k]:
        first -= 1
    x, y = line.positions[first].tolist()
    return float(line.starts[k]), (float(x), float(y))


def _place(position: tuple[float, float]) -> str:
    return f"({position[0]:.4g}, {position[1]:.4g})"


def _times(count: int) -> str:
    return "once" if count == 1 else f"{count} times"


def _visits(line: Timeline, held: BoolArray) -> tuple[int, float | None, float]:
    """Visits (runs where ``held``), when the last began, and the longest time between them.

    Gaps run from the start of the trace to the first visit, between visits, and from the
    last visit to the end of the trace.
    """
    found = runs(held)
    begin, finish = float(line.starts[0]), float(line.ends[-1])
    if not found:
        return 0, None, finish - begin
    marks = [begin]
    for first, last in found:
        marks.extend([float(line.starts[first]), float(line.ends[last])])
    marks.append(finish)
    gaps = [marks[i + 1] - marks[i] for i in range(0, len(marks), 2)]
    return len(found), float(line.starts[found[-1][0]]), max(gaps)


def _globally_violations(
    conjunct: Formula, inner: Formula, broken: BoolArray, line: Timeline
) -> list[Violation]:
    text = to_text(conjunct)
    found = []
    for first, last in runs(broken):
        time, position = _at(line, first)
        if isinstance(inner, Eventually):
            message = (
                f"`{to_text(inner.arg)}` never holds again after {line.clock.at(time)} "
                f"(from {_place(position)}), so `{text}` fails"
            )
            found.append(
                Violation(
                    conjunct=text, time=line.clock.stamp(time), position=position, message=message
                )
            )
            continue
        true = [line.names[i] for i in np.flatnonzero(line.labels[first])]
        inside = [name for name in true if name not in line.signals]
        forbidden = [
            n.arg.name
            for n in inner.walk()
            if isinstance(n, Not) and isinstance(n.arg, Prop) and n.arg.name in true
        ]
        if forbidden and forbidden[0] in line.signals:
            message = f"`{forbidden[0]}` is true at {line.clock.at(time)} at {_place(position)}"
        elif forbidden:
            message = f"entered {forbidden[0]} at {line.clock.at(time)} at {_place(position)}"
        else:
            where = ", ".join(inside) if inside else "free space"
            message = (
                f"`{to_text(inner)}` stops holding at {line.clock.at(time)} at "
                f"{_place(position)} "
                f"(in {where})"
            )
        duration = float(line.ends[last]) - time
        message += f" for {duration:.4g} s while `{text}` must hold"
        found.append(
            Violation(
                conjunct=text, time=line.clock.stamp(time), position=position, message=message
            )
        )
    return found


def _other_violation(
    conjunct: Formula, value: Callable[[Formula], Value], line: Timeline
) -> Violation:
    text = to_text(conjunct)
    size = line.size
    match conjunct:
        case Eventually(arg):
            return Violation(
                conjunct=text,
                time=None,
                position=None,
                message=f"`{to_text(arg)}` never holds, so `{text}` fails",
            )
        case Until(left, right):
            right_never = value(right)[1][:size] < 0
            left_fails = value(left)[1][:size] < 0
            bad = np.flatnonzero(left_fails & right_never)
            # the first instant where neither holds, if b never held before it
            if len(bad) and right_never[: int(bad[0]) + 1].all():
                time, position = _at(line, int(bad[0]))
                return Violation(
                    conjunct=text,
                    time=line.clock.stamp(time),
                    position=position,
                    message=f"`{to_text(left)}` stops holding at {line.clock.at(time)} at "
                    f"{_place(position)} before `{to_text(right)}` holds",
                )
            if right_never.all():
                return Violation(
                    conjunct=text,
                    time=None,
                    position=None,
                    message=f"`{to_text(right)}` never holds, so `{text}` fails",
                )
        case _:
            pass  # no specific explanation for the other operators
    return Violation(
        conjunct=text, time=None, position=None, message=f"`{text}` does not hold on this trace"
    )


def _progress(
    conjunct: Formula, outcome: Outcome, value: Callable[[Formula], Value], line: Timeline
) -> ConjunctReport:
    text = to_text(conjunct)
    size = line.size

    def held(f: Formula) -> BoolArray:
        truth: BoolArray = value(f)[0][:size] > 0
        return truth

    words = {"satisfied": "holds", "violated": "fails", "inconclusive": "pending"}
    match conjunct:
        case Globally(Eventually(goal)):
            count, last, gap = _visits(line, held(goal))
            if last is not None:  # visited at least once
                progress = (
                    f"visited {_times(count)}, last at {line.clock.at(last)}, "
                    f"longest gap {gap:.4g} s"
                )
            else:
                progress = f"never visited in {gap:.4g} s"
            return ConjunctReport(
                conjunct=text,
                outcome=outcome,
                progress=progress,
                visits=count,
                last_visit=None if last is None else line.clock.stamp(last),
                longest_gap=gap,
            )
        case Eventually(arg):
            found = runs(held(arg))
            if found:
                time = float(line.starts[found[0][0]])
                progress = f"done at {line.clock.at(time)}"
            else:
                progress = "pending" if outcome == "inconclusive" else "never done"
            return ConjunctReport(
                conjunct=text, outcome=outcome, progress=progress, visits=len(found)
            )
        case Globally(arg):
            broken = runs(value(arg)[1][:size] < 0)
            if broken:
                time = float(line.starts[broken[0][0]])
                progress = f"broken {_times(len(broken))}, first at {line.clock.at(time)}"
            else:
                progress = "held so far" if outcome == "inconclusive" else "held throughout"
            return ConjunctReport(conjunct=text, outcome=outcome, progress=progress)
        case Until(_, right):
            found = runs(held(right))
            if found and outcome == "satisfied":
                reached = float(line.starts[found[0][0]])
                progress = f"`{to_text(right)}` reached at {line.clock.at(reached)}"
            else:
                progress = words[outcome]
            return ConjunctReport(conjunct=text, outcome=outcome, progress=progress)
        case _:
            return ConjunctReport(conjunct=text, outcome=outcome, progress=words[outcome])


def conjunct_reports(
    conjuncts: list[Formula],
    outcomes: list[Outcome],
    value: Callable[[Formula], Value],
    line: Timeline,
) -> tuple[list[ConjunctReport], list[Violation]]:
    """A report per conjunct, and every violation (each run of a broken ``G``, for instance)."""
    reports = []
    violations: list[Violation] = []
    for conjunct, outcome in zip(conjuncts, outcomes, strict=True):
        reports.append(_progress(conjunct, outcome, value, line))
        if outcome != "violated":
            continue
        if isinstance(conjunct, Globally):
            broken = value(conjunct.arg)[1][: line.size] < 0
            found = _globally_violations(conjunct, conjunct.arg, broken, line)
            if found:
                violations.extend(found)
                continue
        violations.append(_other_violation(conjunct, value, line))
    return reports, violations


def _seconds(value: float) -> str:
    return f"{seconds(value)} s"


def _response(inner: Formula) -> tuple[Formula, Formula, float] | None:
    """``(trigger, goal, T)`` of ``trigger -> F[0,T] goal`` (or ``!trigger | F[0,T] goal``)."""
    match inner:
        case Implies(trigger, BoundedEventually(goal, interval)) if interval.low == 0:
            return trigger, goal, interval.high
        case Or((Not(trigger), BoundedEventually(goal, interval))) if interval.low == 0:
            return trigger, goal, interval.high
        case _:
            return None


def timed_progress(
    conjunct: Formula,
    outcome: Outcome,
    slack: float | None,
    first_broken: float | None,
    *,
    first_done: float | None = None,
    clock: Clock,
) -> str | None:
    """Progress of a conjunct with time bounds, from its time robustness ``slack``;
    ``first_broken`` (the first instant its ``G`` is broken) and ``first_done`` (a deadline's
    first instant done) are seconds from the log's first sample, as every bound is; ``clock``
    writes them.

    None when the conjunct has no time bound or no time robustness.
    """
    if outcome == "inconclusive":
        if isinstance(conjunct, BoundedEventually):
            return f"pending: deadline t={seconds(conjunct.interval.high)} s"
        return (
            "pending" if first_broken is None else f"pending (broken at {clock.at(first_broken)})"
        )
    if slack is None:
        return None
    where = f" at {clock.at(first_broken)}" if first_broken is not None else ""
    if math.isinf(slack):
        return "holds at any bound" if slack > 0 else "fails at any bound"
    match conjunct:
        case BoundedEventually(_, interval) if math.isfinite(interval.high):
            deadline = interval.high
            if slack >= 0:
                # from the instant itself where it is known: deadline - slack cancels to
                # nothing when the deadline is far
                done = deadline - slack if first_done is None else first_done
                return (
                    f"done at t={seconds(done)} s, {_seconds(deadline - done)} before the "
                    f"deadline t={seconds(deadline)} s"
                )
            return f"deadline t={seconds(deadline)} s missed by {_seconds(-slack)}"
        case Globally(BoundedEventually(goal, interval)) if interval.low == 0:
            gap = interval.high - slack
            return (
                f"longest time without `{to_text(goal)}` {_seconds(gap)} "
                f"(bound {interval.high:.4g} s)"
            )
        case Eventually(BoundedGlobally(goal, interval)) if interval.low == 0:
            stay = interval.high + slack
            return (
                f"longest stay in `{to_text(goal)}` {_seconds(stay)} "
                f"(at least {interval.high:.4g} s)"
            )
        case Globally(inner) if _response(inner) is not None:
            found = _response(inner)
            assert found is not None
            trigger, goal, bound = found
            if isinstance(goal, Not) and goal.arg == trigger:
                return (
                    f"longest stay in `{to_text(trigger)}` {_seconds(bound - slack)} "
                    f"(at most {bound:.4g} s)"
                )
            if slack >= 0:
                return (
                    f"longest wait for `{to_text(goal)}` after `{to_text(trigger)}` "
                    f"{_seconds(bound - slack)} (within {bound:.4g} s)"
                )
            return f"deadline missed by {_seconds(-slack)}{where}"
        case _:
            if slack >= 0:
                return f"holds with {_seconds(slack)} to spare"
            return f"fails by {_seconds(-slack)}{where}"
