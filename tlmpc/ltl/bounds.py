"""Time bounds where the untimed machinery works: refusing them, or relaxing them.

The automaton translation works on untimed LTL, so it refuses ``F[a,b]``, ``G[a,b]`` and
``U[a,b]`` (L045) at the operator's position instead of silently dropping the bound.
``tlmpc verify`` decides time bounds exactly on a trajectory or a log.

The planner plans a bounded task on its **untimed skeleton** (:func:`untimed_skeleton`): a
formula without bounds that every run satisfying the task satisfies too, so "the skeleton has
no plan" is still a proof that the task has none; the compiled trajectory is then checked
against every bound (docs/semantics.md, "Planning with time bounds").
"""

from __future__ import annotations

import math
from typing import assert_never

from tlmpc.base.errors import InvalidInputError, error
from tlmpc.ltl.ast import (
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
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
    bounded_operators,
)
from tlmpc.ltl.printer import to_text

#: At most this many bounded operators are named in one refusal.
MAX_NAMED = 3


def refuse_bounds(formula: Formula, *, file: str | None = None, purpose: str) -> None:
    """Raise L045 for each time-bounded operator of ``formula`` (none: return).

    ``purpose`` says what cannot take the bound (``"planning"``, ``"the automaton"``).
    """
    found = bounded_operators(formula)
    if not found:
        return
    diagnostics = []
    for node in found[:MAX_NAMED]:
        span = node.span
        diagnostics.append(
            error(
                "L045",
                f"{purpose} cannot take the time bound of `{to_text(node)}`",
                hint="tlmpc verify checks time bounds exactly on a trajectory or a log, and "
                "tlmpc compile plans a bounded task on its untimed skeleton and checks every "
                "bound on the compiled trajectory",
                file=file,
                line=span.line if span is not None else None,
                col=span.col if span is not None else None,
            )
        )
    raise InvalidInputError(diagnostics)


def untimed_skeleton(formula: Formula) -> Formula:
    """``formula`` with every time bound relaxed away: a formula without bounds that every
    run satisfying ``formula`` satisfies too (the identity on untimed formulas).

    Where a bounded operator occurs positively it is *weakened*:

    * ``F[a,b] φ`` -> ``F φ``;
    * ``φ U[a,b] ψ`` -> ``φ U ψ``;
    * ``G[0,b] φ`` -> ``φ`` (it holds now), ``G[a,b] φ`` with ``a > 0`` -> ``F φ`` (it holds
      at t + a), and with ``b = inf``: ``G φ`` (``a = 0``, exact) or ``F G φ``.

    Under a negation it is *strengthened* (a stronger formula under a negation is a weaker
    one): ``F[0,b] φ`` -> ``φ``, ``F[a,b] φ`` -> ``G φ``, ``G[a,b] φ`` -> ``G φ``,
    ``φ U[0,b] ψ`` -> ``ψ`` and ``φ U[a,b] ψ`` -> ``G(φ & ψ)``.  An equivalence with a bound
    inside is read as the two implications.  ``F[0,inf]``, ``G[0,inf]`` and ``U[0,inf]`` are
    their untimed operators exactly.
    """
    if not bounded_operators(formula):
        return formula
    return _relax(formula, True)


def holding_skeleton(formula: Formula) -> Formula:
    """``formula`` with its durations made to hold forever: an untimed formula whose runs
    keep every ``G[a,b]`` of the task (where it occurs positively: ``G[a,b] φ`` -> ``G φ``,
    which implies it), the deadlines relaxed as in :func:`untimed_skeleton` (``F[a,b] φ`` ->
    ``F φ``, ``U[a,b]`` -> ``U``: no untimed formula meets a deadline by itself), and the
    bounds under a negation weakened (so that the negation is strengthened).

    A plan of it is a plan of :func:`untimed_skeleton` that also stays where the task asks
    the robot to stay for a while ("stay in X for at least T s" plans as ``F G X``); it may
    have none where the task has one, so the planner then falls back to the skeleton.
    """
    if not bounded_operators(formula):
        return formula
    return _relax(formula, False, deadlines=True)


def _relax(formula: Formula, positive: bool, deadlines: bool = False) -> Formula:
    """The untimed weakening (``positive``) or strengthening of ``formula``; with
    ``deadlines``, ``F[a,b]`` and ``U[a,b]`` take their weakened form either way."""
    match formula:
        case Const() | Prop():
            return formula
        case Not(arg):
            return Not(_relax(arg, not positive, deadlines), span=formula.span)
        case And(args):
            return And(tuple(_relax(a, positive, deadlines) for a in args), span=formula.span)
        case Or(args):
            return Or(tuple(_relax(a, positive, deadlines) for a in args), span=formula.span)
        case Implies(left, right):
            return Implies(
                _relax(left, not positive, deadlines),
                _relax(right, positive, deadlines),
                span=formula.span,
            )
        case Equiv(left, right):
            if not bounded_operators(formula):
                return formula
            both = And((Implies(left, right), Implies(right, left)), span=formula.span)
            return _relax(both, positive, deadlines)
        case Eventually(arg):
            return Eventually(_relax(arg, positive, deadlines), span=formula.span)
        case Globally(arg):
            return Globally(_relax(arg, positive, deadlines), span=formula.span)
        case Until(left, right) | Release(left, right) | WeakUntil(left, right):
            return type(formula)(
                _relax(left, positive, deadlines),
                _relax(right, positive, deadlines),
                span=formula.span,
            )
        case StrongRelease(left, right):
            return StrongRelease(
                _relax(left, positive, deadlines),
                _relax(right, positive, deadlines),
                span=formula.span,
            )
        case BoundedEventually(arg, interval):
            inner = _relax(arg, positive, deadlines)
            if positive or deadlines:
                return Eventually(inner, span=formula.span)
            return inner if interval.low == 0.0 else Globally(inner, span=formula.span)
        case BoundedGlobally(arg, interval):
            inner = _relax(arg, positive, deadlines)
            if not positive:
                return Globally(inner, span=formula.span)
            if math.isinf(interval.high):
                always = Globally(inner, span=formula.span)
                return always if interval.low == 0.0 else Eventually(always, span=formula.span)
            return inner if interval.low == 0.0 else Eventually(inner, span=formula.span)
        case BoundedUntil(left, right, interval):
            first, second = _relax(left, positive, deadlines), _relax(right, positive, deadlines)
            if positive or deadlines:
                return Until(first, second, span=formula.span)
            if interval.low == 0.0:
                return second
            return Globally(And((first, second)), span=formula.span)
        case _:
            assert_never(formula)
