"""Time robustness: by how many seconds a task's time bounds held or failed.

Tightening a formula by ``d`` seconds moves the far end of every finite bound against it:
where the operator occurs positively, ``F[a,b]`` and ``U[a,b]`` become ``F[a,b-d]`` and
``U[a,b-d]`` (less time to get there) and ``G[a,b]`` becomes ``G[a,b+d]`` (longer to hold);
under a negation the other way round.  A window that shrinks past its start is empty (an
``F`` over it is false, a ``G`` true).  Every operator is monotone in its window, so the
verdict only gets worse as ``d`` grows.

The **time robustness** of a satisfied formula is the largest ``d >= 0`` for which the
tightened formula is still satisfied (``inf``: any; its bounds have no say); of a violated
one, minus the smallest ``d >= 0`` by which loosening it (tightening by ``-d``) stops the
violation (``-inf``: no loosening does).  Inconclusive verdicts have none.  For the task
phrases it reads directly: ``visit X within T s`` done at time s has ``T - s``; ``visit X at
least every T s`` has ``T`` minus the longest gap; ``stay in X for at least T s`` the longest
stay minus ``T``.

It is found by bisection with the exact evaluator, to :data:`STEPS` halvings of the search
range (a fixed number of evaluations: the same bytes on any machine).  Formulas where a bound
sits under ``<->`` (both polarities) have none.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence
from typing import assert_never

from tlmpc.ltl.ast import (
    BOUNDED,
    FALSE,
    TRUE,
    And,
    BoundedEventually,
    BoundedGlobally,
    BoundedUntil,
    Const,
    Equiv,
    Eventually,
    Formula,
    Globally,
    Implies,
    Interval,
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
    bounded_operators,
)

#: Bisection steps: the search range (the trace's duration and the bounds) is halved this many
#: times, to about a millionth of a millionth of it.
STEPS = 40

#: A deadline's time is first bracketed by window ends this many times apart (2^10: at most
#: about a hundred steps up to the largest float, each bracket 2^10 times its lower end).
GALLOP = 1024.0


class BothPolarities(ValueError):
    """A time bound under ``<->``: tightening it has no direction."""


def _shrink(interval: Interval, amount: float) -> Interval | None:
    """``[a, b - amount]`` (None: empty); infinite ends stay."""
    if math.isinf(interval.high):
        return interval
    high = interval.high - amount
    if high < interval.low:
        return None
    return Interval(interval.low, high)


def tighten(
    formula: Formula,
    amount: float,
    positive: bool = True,
    *,
    only: Formula | None = None,
    high: float | None = None,
) -> Formula:
    """``formula`` with every finite bound made ``amount`` seconds harder to meet (with
    ``only``: that bounded node alone, the very object, not an equal one elsewhere; with
    ``only`` and ``high``: that node's window ends at ``high`` instead, exactly, whatever
    ``amount`` says)."""

    def again(f: Formula, sign: bool = positive) -> Formula:
        return tighten(f, amount, sign, only=only, high=high)

    def moved(interval: Interval, by: float) -> Interval | None:
        if high is not None and only is not None:
            return Interval(interval.low, high)
        return _shrink(interval, by)

    if only is not None and formula is not only and isinstance(formula, BOUNDED):
        # another bound: kept as it is, its operands still searched for ``only``
        match formula:
            case BoundedEventually(arg, interval) | BoundedGlobally(arg, interval):
                return type(formula)(again(arg), interval)
            case BoundedUntil(left, right, interval):
                return BoundedUntil(again(left), again(right), interval)

    match formula:
        case Const() | Prop():
            return formula
        case Not(arg):
            return Not(again(arg, not positive))
        case And(args):
            return And(tuple(again(a) for a in args))
        case Or(args):
            return Or(tuple(again(a) for a in args))
        case Implies(left, right):
            return Implies(again(left, not positive), again(right))
        case Equiv(left, right):
            if only is not None and not any(node is only for node in formula.walk()):
                return formula  # the one bound that moves is elsewhere: nothing here does
            if bounded_operators(formula):
                raise BothPolarities(str(formula))
            return formula
        case Eventually(arg) | Globally(arg):
            return type(formula)(again(arg))
        case Until(left, right) | Release(left, right) | WeakUntil(left, right):
            return type(formula)(again(left), again(right))
        case StrongRelease(left, right):
            return StrongRelease(again(left), again(right))
        case BoundedEventually(arg, interval):
            window = moved(interval, amount if positive else -amount)
            return FALSE if window is None else BoundedEventually(again(arg), window)
        case BoundedUntil(left, right, interval):
            window = moved(interval, amount if positive else -amount)
            if window is None:
                return FALSE
            return BoundedUntil(again(left), again(right), window)
        case BoundedGlobally(arg, interval):
            window = moved(interval, -amount if positive else amount)
            return TRUE if window is None else BoundedGlobally(again(arg), window)
        case _:
            assert_never(formula)


def reach(formula: Formula) -> float:
    """How far past t the value of ``formula`` at t looks: the largest sum of bounds along a
    path of nested operators (``inf`` with an unbounded temporal operator or bound)."""
    match formula:
        case Const() | Prop():
            return 0.0
        case Not() | And() | Or() | Implies() | Equiv():
            return max(reach(c) for c in formula.children())
        case BoundedEventually(_, interval) | BoundedGlobally(_, interval):
            return interval.high + max(reach(c) for c in formula.children())
        case BoundedUntil(_, _, interval):
            return interval.high + max(reach(c) for c in formula.children())
        case Eventually() | Globally() | Until() | Release() | WeakUntil() | StrongRelease():
            return math.inf
        case _:
            assert_never(formula)


def horizon(formula: Formula, duration: float, *, without: Formula | None = None) -> float:
    """How far a search for the time robustness must look: past the trace's duration plus
    every finite bound (the largest float when that sum is past it); ``without`` (a bounded
    node of ``formula``, the very object): every finite bound but that one's."""
    bounds = [
        n.interval.high
        for n in bounded_operators(formula)
        if isinstance(n, BoundedEventually | BoundedGlobally | BoundedUntil)
        and math.isfinite(n.interval.high)
        and n is not without
    ]
    total = duration + sum(bounds)
    # Strictly past every edge however large the sum: past 2**53 s a "+ 1" is rounded away,
    # and an edge exactly at the horizon would read as "any amount" (inf).
    return min(math.nextafter(total + 1.0, math.inf), sys.float_info.max)


def time_robustness(
    formula: Formula,
    outcome: str,
    outcome_of: Callable[[Formula], str],
    reach: float,
    *,
    only: Formula | None = None,
) -> float | None:
    """The time robustness of ``formula`` whose verdict is ``outcome``; ``outcome_of`` gives the
    verdict of a tightened formula; ``reach`` bounds the search (see :func:`horizon`).  With
    ``only`` (a bounded node of ``formula``): the slack of that one bound, the others kept."""
    if outcome == "inconclusive" or not bounded_operators(formula):
        return None
    try:
        # Tightened by 0 every window keeps its operand, so this meets every `<->` that any
        # amount of the search can: a larger amount empties an outer window (replaced by a
        # constant) and hides the `<->` below it until the bisection tries a smaller one.
        tighten(formula, 0.0, only=only)
        if outcome == "satisfied":

            def good(amount: float) -> bool:
                return outcome_of(tighten(formula, amount, only=only)) == "satisfied"

            if good(reach):
                return math.inf
            low, high = 0.0, reach
        else:

            def good(amount: float) -> bool:
                return outcome_of(tighten(formula, -amount, only=only)) != "violated"

            if not good(reach):
                return -math.inf
            low, high = 0.0, reach
    except BothPolarities:
        return None
    # outcome == satisfied: good(low) holds, good(high) fails; find the edge.
    # outcome == violated: good(low) fails, good(high) holds.
    for _ in range(STEPS):
        # (low + high) / 2 overflows to inf once both pass half the largest float
        middle = low + (high - low) / 2.0
        if (outcome == "satisfied") == good(middle):
            low = middle
        else:
            high = middle
    # The edge is known to reach / 2**STEPS; ten significant digits say no more than that (and
    # print -0.5 rather than -0.49999999999999983).
    found = low if outcome == "satisfied" else -high
    shown = float(f"{found:.10g}")
    return shown if math.isfinite(shown) else found  # (rounded past the largest float)


def tightest_deadline(
    formula: Formula,
    deadline: BoundedEventually | BoundedUntil,
    outcome_of: Callable[[Formula], str],
    duration: float,
) -> float | None:
    """The earliest far end ``h`` of ``deadline``'s window (a node of the satisfied
    ``formula`` whose satisfaction only grows with that end: an ``F[0,T]`` or ``U[0,T]``
    occurring positively) for which ``formula`` is still satisfied, the other bounds kept:
    the time the trace meets that deadline at.

    That is ``T`` less the bound's slack, searched here on the window's end itself: ``T -
    slack`` cancels when ``T`` dwarfs the trace (the slack of ``F[0,1e12] b``, found to a
    2^-40 of 1e12 s and shown to ten digits, would put ``b`` at 0 s).  The end sought lies
    before the trace's duration plus the other bounds: past them the trace has nothing new
    for the window (a stay is constant, a loop repeats).  Up to that end, ends growing
    :data:`GALLOP` times from the trace's duration bracket it (a few steps, however large
    the other bounds), and :data:`STEPS` halvings narrow the bracket to 2^-30 of the end
    found.  None when the formula is not satisfied at the range's end (a window the range
    does not cover): the caller keeps ``T - slack``."""
    low = deadline.interval.low

    def good(end: float) -> bool:
        return outcome_of(tighten(formula, 0.0, only=deadline, high=end)) == "satisfied"

    top = max(low, min(deadline.interval.high, horizon(formula, duration, without=deadline)))
    try:
        if not good(top):
            return None
        if good(low):
            return low
    except BothPolarities:
        return None
    early, late = low, top  # fails at `early`, holds at `late`
    reach_out = low + duration + 1.0
    while reach_out < late:
        if good(reach_out):
            late = reach_out
            break
        early, reach_out = reach_out, low + (reach_out - low) * GALLOP
    for _ in range(STEPS):
        middle = early + (late - early) / 2.0
        if good(middle):
            late = middle
        else:
            early = middle
    return late  # (not rounded to fewer digits: that could end it before the edge, unmet)


def conjunction_robustness(
    conjuncts: Sequence[tuple[Formula, str, float | None]], outcome: str
) -> float | None:
    """The time robustness of a conjunction whose verdict is ``outcome``, from each conjunct's
    ``(formula, verdict, time robustness)``: what :func:`time_robustness` finds for the whole,
    without searching it again.  Tightening distributes over ``&`` and the verdict of ``&`` is
    the least of its conjuncts', so the conjunction tightened by ``d`` is satisfied exactly when
    every conjunct is (the least slack), and loosened by ``d`` it stops failing exactly when
    every failing conjunct does (the least, an untimed failing one never: ``-inf``)."""
    timed = [c for c in conjuncts if bounded_operators(c[0])]
    if outcome == "inconclusive" or not timed:
        return None
    try:
        for formula, _, _ in timed:
            tighten(formula, 0.0)
    except BothPolarities:
        return None
    if outcome == "satisfied":
        slacks = [slack for _, _, slack in timed]
    else:
        slacks = [
            slack if bounded_operators(formula) else -math.inf
            for formula, verdict, slack in conjuncts
            if verdict == "violated"
        ]
    if any(slack is None for slack in slacks):
        return None  # (a conjunct's verdict contradicts the conjunction's)
    return min(slack for slack in slacks if slack is not None)
