"""A definition-level dense-time MTL evaluator, independent of tlmpc's code.

A trace is a piecewise-constant signal whose instants of change (and every time bound) are
multiples of a quantum ``q`` seconds.  Then every sub-formula changes its value only at
multiples of ``q`` as well (a bound shifts a change by a multiple of ``q``), so time is read on
a grid of *ticks* of ``q / 2``: an even tick is an instant ``j q``; an odd tick stands for the
open stretch ``(j q, (j + 1) q)``, on which everything is constant.  Each operator is then
its definition, quantified over ticks (integers: no rounding anywhere):

* ``F[a,b] x`` at ``t``: some tick ``s`` in ``[t + a, t + b]`` has ``x`` (the window's ends
  are ticks, and the ticks inside it stand for exactly the instants and stretches it meets);
* ``G[a,b] x``: every such tick;
* ``x U[a,b] y``: some tick ``s`` in the window has ``y``, and ``x`` holds on ``[t, s)``: at
  every tick ``r`` with ``t <= r < s``, and at ``s`` itself when ``s`` is a stretch and
  ``s > t`` (the instants of that stretch before the witness are in ``[t, s)``); untimed
  ``U`` is ``U[0,inf]``, ``F x = true U x``; the others are their definitions.

After the last instant the trace either stays (its last instant's letter forever) or loops
(from a given instant, with its period).  Quantifiers run to a horizon far enough that the
signals beyond it repeat (a loop: several periods; a stay: past every bound): the verdicts
asked for (at ticks up to the trace's end) are exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

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
)


@dataclass(frozen=True)
class TickTrace:
    """Instants ``breaks`` (even ticks, increasing, from 0), a letter per piece (instant,
    stretch, instant, ...), and the ending: ``loop`` None (a stay on the last instant) or the
    index of the loop's first instant in ``breaks`` with ``end`` the wrap tick."""

    breaks: tuple[int, ...]
    letters: tuple[frozenset[str], ...]
    loop: int | None = None
    end: int | None = None

    def letter(self, tick: int) -> frozenset[str]:
        """The letter at ``tick``."""
        last = self.breaks[-1]
        if self.loop is None:
            if tick >= last:
                return self.letters[2 * len(self.breaks) - 2]
        else:
            assert self.end is not None
            start = self.breaks[self.loop]
            if tick >= self.end:
                tick = start + (tick - start) % (self.end - start)
            if tick > last:
                return self.letters[-1]
        for index, when in enumerate(self.breaks):
            if tick == when:
                return self.letters[2 * index]
            if index + 1 < len(self.breaks) and when < tick < self.breaks[index + 1]:
                return self.letters[2 * index + 1]
        raise AssertionError(tick)


def _ticks(seconds: float, quantum: float) -> int:
    ticks = seconds / (quantum / 2)
    assert ticks == int(ticks), (seconds, quantum)
    return int(ticks)


def _bounds(formula: Formula) -> list[float]:
    found = []
    for node in formula.walk():
        if isinstance(node, BoundedEventually | BoundedGlobally | BoundedUntil):
            found.extend([node.interval.low, node.interval.high])
    return [b for b in found if math.isfinite(b)]


def dense_values(formula: Formula, trace: TickTrace, quantum: float) -> dict[int, bool]:
    """The truth of ``formula`` at every tick from 0 to the trace's end (its last instant, or
    the loop's wrap)."""
    last = trace.breaks[-1] if trace.end is None else trace.end
    operators = sum(1 for n in formula.walk() if not isinstance(n, Prop | Const))
    period = 0 if trace.end is None else trace.end - trace.breaks[trace.loop or 0]
    spread = sum(_ticks(b, quantum) for b in _bounds(formula))
    horizon = last + spread + operators * (period + 2) + 4
    values, limit = _evaluate(formula, trace, quantum, horizon, period)
    assert limit >= last, (limit, last)
    return {t: values[t] for t in range(last + 1)}


def _evaluate(
    formula: Formula, trace: TickTrace, quantum: float, horizon: int, period: int
) -> tuple[list[bool], int]:
    """Values at ticks 0..horizon, and the last tick up to which they are exact.

    A window reaching past where its operand is exact makes the result exact only up to that
    much earlier; a quantifier over the whole future looks as far as its operand is exact,
    which is enough where the signals have become constant (a stay) or periodic (a loop: one
    period less is exact)."""
    size = horizon + 1

    def ev(f: Formula) -> tuple[list[bool], int]:
        return _evaluate(f, trace, quantum, horizon, period)

    def until(
        a: list[bool], b: list[bool], low: int, high: int | None, limit: int
    ) -> tuple[list[bool], int]:
        out = []
        for t in range(size):
            found = False
            stop = limit if high is None else min(limit, t + high)
            held = True  # a on every tick of [t, s)
            for s in range(t, stop + 1):
                if s > t:
                    held = held and a[s - 1]
                if not held:
                    break
                if s >= t + low and b[s] and (s == t or s % 2 == 0 or a[s]):
                    found = True
                    break
            out.append(found)
        exact = limit - high if high is not None else limit - low - period - 2
        return out, exact

    def negate(value: tuple[list[bool], int]) -> tuple[list[bool], int]:
        return [not v for v in value[0]], value[1]

    def combine(parts: list[tuple[list[bool], int]], op: str) -> tuple[list[bool], int]:
        limit = min(p[1] for p in parts)
        rows = list(zip(*(p[0] for p in parts), strict=True))
        if op == "and":
            return [all(r) for r in rows], limit
        if op == "or":
            return [any(r) for r in rows], limit
        if op == "implies":
            return [not r[0] or r[1] for r in rows], limit
        return [r[0] == r[1] for r in rows], limit

    everywhere = ([True] * size, horizon)
    match formula:
        case Const(value):
            return [value] * size, horizon
        case Prop(name):
            return [name in trace.letter(t) for t in range(size)], horizon
        case Not(arg):
            return negate(ev(arg))
        case And(args):
            return combine([ev(a) for a in args], "and")
        case Or(args):
            return combine([ev(a) for a in args], "or")
        case Implies(left, right):
            return combine([ev(left), ev(right)], "implies")
        case Equiv(left, right):
            return combine([ev(left), ev(right)], "equiv")
        case Until(left, right):
            (a, la), (b, lb) = ev(left), ev(right)
            return until(a, b, 0, None, min(la, lb))
        case Eventually(arg):
            b, lb = ev(arg)
            return until(everywhere[0], b, 0, None, lb)
        case Globally(arg):
            b, lb = negate(ev(arg))
            return negate(until(everywhere[0], b, 0, None, lb))
        case Release(left, right):
            (a, la), (b, lb) = negate(ev(left)), negate(ev(right))
            return negate(until(a, b, 0, None, min(la, lb)))
        case WeakUntil(left, right):
            (a, la), (b, lb) = ev(left), ev(right)
            strong = until(a, b, 0, None, min(la, lb))
            always = negate(until(everywhere[0], [not v for v in a], 0, None, la))
            return combine([strong, always], "or")
        case StrongRelease(left, right):
            (a, la), (b, lb) = ev(left), ev(right)
            both = [x and y for x, y in zip(a, b, strict=True)]
            return until(b, both, 0, None, min(la, lb))
        case BoundedEventually(arg, interval) | BoundedGlobally(arg, interval):
            low = _ticks(interval.low, quantum)
            high = None if math.isinf(interval.high) else _ticks(interval.high, quantum)
            x, lx = ev(arg)
            if isinstance(formula, BoundedEventually):
                return until(everywhere[0], x, low, high, lx)
            return negate(until(everywhere[0], [not v for v in x], low, high, lx))
        case BoundedUntil(left, right, interval):
            low = _ticks(interval.low, quantum)
            high = None if math.isinf(interval.high) else _ticks(interval.high, quantum)
            (a, la), (b, lb) = ev(left), ev(right)
            return until(a, b, low, high, min(la, lb))
        case _:
            raise TypeError(formula)
