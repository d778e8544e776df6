"""Time bounds against independent dense-time monitors: rtamt and reelay.

Both read a signal as piecewise constant and right-continuous (a sample's value holds until
the next sample): the verifier's right-continuous convention, where an instant carries the
letter of the stretch after it.

* **rtamt** (``StlDenseTimeSpecification``) evaluates future-time MTL.  At the end of a log
  it evaluates each window on the part of it that the log covers, which is not the
  definition: a window running past the end is decided as if the log said all there is.
  Where every window of the formula at t = 0 lies inside the log, rtamt is the definition,
  and the verifier's three-valued answer must be decided and agree.  Where a window runs
  past the end, the verifier answers inconclusive, and the definition-level oracle confirms
  that continuations go both ways while rtamt commits to one of them.
* **reelay** monitors past-time MTL.  ``F[a,b] x`` at 0 on a log that ends at T is
  ``once[T-b, T-a] x`` at T, and ``G[a,b] x`` is ``historically[T-b, T-a] x``: single
  bounded operators over propositional arguments are checked that way.
"""

from __future__ import annotations

import numpy as np
import pytest
from dense_mtl import TickTrace, dense_values
from hypothesis import given, settings
from hypothesis import strategies as st
from test_verify_dense import PROPS, QUANTUM, TICK, letters, ours

from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedGlobally,
    Formula,
    Interval,
    Not,
    Or,
    Prop,
)
from tlmpc.ltl.parser import parse_ltl
from tlmpc.ltl.printer import to_text
from tlmpc.verify.semantics import three_valued

finite_intervals = st.builds(
    lambda low, width: Interval(low, low + width),
    st.sampled_from([0.0, 0.25, 0.5, 1.0]),
    st.sampled_from([0.0, 0.25, 0.5, 1.0, 2.0]),
)


def finite_formulas() -> st.SearchStrategy[Formula]:
    """Formulas whose every operator has a finite bound (rtamt decides them in the log)."""
    leaves = st.sampled_from([Prop(p) for p in PROPS])

    def extend(inner: st.SearchStrategy[Formula]) -> st.SearchStrategy[Formula]:
        return st.one_of(
            st.builds(BoundedEventually, inner, finite_intervals),
            st.builds(BoundedGlobally, inner, finite_intervals),
            st.builds(Not, inner),
            st.builds(lambda a, b: And((a, b)), inner, inner),
            st.builds(lambda a, b: Or((a, b)), inner, inner),
        )

    return st.recursive(leaves, extend, max_leaves=5)


def _reach(formula: Formula) -> float:
    """How far past t the formula looks (the sum of the bounds along its deepest path)."""
    match formula:
        case BoundedEventually(arg, interval) | BoundedGlobally(arg, interval):
            return interval.high + _reach(arg)
        case _:
            return max((_reach(c) for c in formula.children()), default=0.0)


def _rtamt_text(f: Formula) -> str:
    match f:
        case Prop(name):
            return f"({name} >= 0)"
        case Not(arg):
            return f"(not {_rtamt_text(arg)})"
        case And(args):
            return "(" + " and ".join(_rtamt_text(a) for a in args) + ")"
        case Or(args):
            return "(" + " or ".join(_rtamt_text(a) for a in args) + ")"
        case BoundedEventually(arg, interval):
            return f"(eventually[{interval.low:g},{interval.high:g}] {_rtamt_text(arg)})"
        case BoundedGlobally(arg, interval):
            return f"(always[{interval.low:g},{interval.high:g}] {_rtamt_text(arg)})"
        case _:
            raise TypeError(f)


def _rtamt_at_start(formula: Formula, trace: TickTrace) -> float:
    import rtamt

    spec = rtamt.StlDenseTimeSpecification()
    for p in PROPS:
        spec.declare_var(p, "float")
    spec.spec = _rtamt_text(formula)
    spec.parse()
    signals = []
    for p in PROPS:
        # the letter of the stretch after each instant (right-continuous), and the last's own
        values = [trace.letters[2 * i + 1] for i in range(len(trace.breaks) - 1)]
        values.append(trace.letters[-1])
        pairs = zip(trace.breaks, values, strict=True)
        samples = [[t * TICK, 1.0 if p in v else -1.0] for t, v in pairs]
        signals.append([p, samples])
    result = spec.evaluate(*signals)
    return float(result[0][1])


@st.composite
def right_continuous_logs(draw: st.DrawFn, length: float) -> TickTrace:
    """An open log at least ``length`` seconds long whose instants carry the next letter."""
    breaks = [0]
    while breaks[-1] * TICK < length + 1.0:
        breaks.append(breaks[-1] + draw(st.sampled_from([2, 4, 6])))
    stretches = draw(st.lists(letters, min_size=len(breaks), max_size=len(breaks)))
    word: list[frozenset[str]] = []
    for index in range(len(breaks)):
        word.append(stretches[index])  # the instant: the letter of the stretch after it
        if index + 1 < len(breaks):
            word.append(stretches[index])
    return TickTrace(tuple(breaks), tuple(word))


@settings(deadline=None, max_examples=100)
@given(finite_formulas(), st.data())
def test_rtamt_agrees_where_the_log_covers_every_window(
    formula: Formula, data: st.DataObject
) -> None:
    trace = data.draw(right_continuous_logs(_reach(formula)))
    verdict = int(three_valued(ours(formula, trace, "open")(formula))[0])
    assert verdict != 0, to_text(formula)
    robustness = _rtamt_at_start(formula, trace)
    assert (robustness > 0) == (verdict == 1), (to_text(formula), trace, robustness)
    assert dense_values(formula, trace, QUANTUM)[0] == (verdict == 1)


@pytest.mark.parametrize(
    ("text", "rtamt_says"),
    [
        ("G[0,5] a", 1),  # a held for the 3 s logged; the next 2 s are unknown
        ("F[0,5] b", -1),  # b not yet; it may still come before 5 s
    ],
)
def test_rtamt_commits_past_the_log_where_the_definition_does_not(
    text: str, rtamt_says: int
) -> None:
    trace = TickTrace((0, 24), (frozenset({"a"}), frozenset({"a"}), frozenset({"a"})))
    formula = parse_ltl(text)
    assert np.sign(_rtamt_at_start(formula, trace)) == rtamt_says
    assert int(three_valued(ours(formula, trace, "open")(formula))[0]) == 0
    # the definition: continuations either way
    keep = TickTrace((0, 24, 48), trace.letters + (frozenset({"a"}),) * 2)
    change = TickTrace((0, 24, 48), trace.letters + (frozenset({"b"}),) * 2)
    assert {dense_values(formula, keep, QUANTUM)[0], dense_values(formula, change, QUANTUM)[0]} == {
        True,
        False,
    }


def _reelay_at_end(pattern: str, trace: TickTrace) -> bool:
    import reelay

    monitor = reelay.dense_timed_monitor(pattern=pattern)
    value = None
    # reelay reports a segment once the next update arrives: one more update, a tick after the
    # end, reports the value from the end on
    instants = [*trace.breaks, trace.breaks[-1] + 1]
    for index, when in enumerate(instants):
        letter = trace.letters[2 * min(index, len(trace.breaks) - 1)]
        for change in monitor.update({"time": when * TICK, **{p: p in letter for p in PROPS}}):
            if change["time"] <= trace.breaks[-1] * TICK:
                value = bool(change["value"])
    assert value is not None
    return value


def _reelay_text(f: Formula) -> str:
    match f:
        case Prop(name):
            return f"{{{name}}}"
        case Not(arg):
            return f"(not {_reelay_text(arg)})"
        case And(args):
            return "(" + " and ".join(_reelay_text(a) for a in args) + ")"
        case Or(args):
            return "(" + " or ".join(_reelay_text(a) for a in args) + ")"
        case _:
            raise TypeError(f)


propositional = st.recursive(
    st.sampled_from([Prop(p) for p in PROPS]),
    lambda inner: st.one_of(
        st.builds(Not, inner),
        st.builds(lambda a, b: And((a, b)), inner, inner),
        st.builds(lambda a, b: Or((a, b)), inner, inner),
    ),
    max_leaves=3,
)


@settings(deadline=None, max_examples=100)
@given(propositional, finite_intervals, st.booleans(), st.data())
def test_reelay_past_time_dual_agrees(
    inner: Formula, interval: Interval, eventually: bool, data: st.DataObject
) -> None:
    pytest.importorskip("reelay")
    trace = data.draw(right_continuous_logs(interval.high))
    end = trace.breaks[-1] * TICK
    formula: Formula = (
        BoundedEventually(inner, interval) if eventually else BoundedGlobally(inner, interval)
    )
    operator = "once" if eventually else "historically"
    low, high = end - interval.high, end - interval.low
    assert low > 0
    pattern = f"{operator}[{low:g}:{high:g}]{_reelay_text(inner)}"
    verdict = int(three_valued(ours(formula, trace, "open")(formula))[0])
    assert verdict != 0
    assert _reelay_at_end(pattern, trace) == (verdict == 1), (to_text(formula), pattern, trace)
