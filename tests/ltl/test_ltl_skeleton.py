"""The untimed skeleton the planner plans a bounded task on: every run that satisfies the task
satisfies its skeleton (checked with the definition-level dense-time evaluator), and the
skeleton has no bounds."""

from __future__ import annotations

import pytest
from dense_mtl import TickTrace, dense_values
from hypothesis import given, settings
from hypothesis import strategies as st
from strategies import bounded_formulas, formulas

from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedGlobally,
    BoundedUntil,
    Equiv,
    Eventually,
    Formula,
    Globally,
    Implies,
    Not,
    Or,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
    bounded_operators,
)
from tlmpc.ltl.bounds import holding_skeleton, untimed_skeleton
from tlmpc.ltl.parser import parse_ltl


@st.composite
def traces(draw: st.DrawFn) -> TickTrace:
    """Stays and loops with change instants on a quarter-second grid."""
    breaks = [0]
    for gap in draw(st.lists(st.sampled_from([2, 4, 8]), max_size=4)):
        breaks.append(breaks[-1] + gap)
    count = 2 * len(breaks) - 1
    letters = st.frozensets(st.sampled_from(["a", "b", "c"]))
    word = tuple(draw(st.lists(letters, min_size=count, max_size=count)))
    if len(breaks) >= 2 and draw(st.booleans()):
        loop = draw(st.integers(0, len(breaks) - 2))
        return TickTrace(tuple(breaks), word, loop=loop, end=breaks[-1])
    return TickTrace(tuple(breaks), word)


@settings(max_examples=300)
@given(bounded_formulas(("a", "b", "c"), max_leaves=5), traces())
def test_the_skeleton_is_implied(formula: Formula, trace: TickTrace) -> None:
    skeleton = untimed_skeleton(formula)
    assert not bounded_operators(skeleton)
    values = dense_values(formula, trace, 0.25)
    relaxed = dense_values(skeleton, trace, 0.25)
    assert all(relaxed[t] for t, held in values.items() if held)


@given(formulas(("a", "b")))
def test_untimed_formulas_are_their_own_skeleton(formula: Formula) -> None:
    assert untimed_skeleton(formula) is formula


@pytest.mark.parametrize(
    ("task", "skeleton"),
    [
        ("F[0,30] dock", "F dock"),
        ("G F[0,40] a", "G F a"),
        ("F G[0,5] a", "F a"),
        ("G(a -> F[0,5] !a)", "G(a -> F !a)"),
        ("G(a -> F[0,30] b)", "G(a -> F b)"),
        ("G[2,inf] a", "F G a"),
        ("G[0,inf] a", "G a"),
        ("a U[0,5] b", "a U b"),
        ("!F[0,5] a", "!a"),
        ("!F[1,5] a", "!G a"),
        ("!G[1,5] a", "!G a"),
        ("!(a U[0,5] b)", "!b"),
        ("!(a U[1,5] b)", "!G(a & b)"),
        ("F[0,5] a <-> b", "(F[0,5] a -> b) & (b -> F[0,5] a)"),
    ],
)
def test_skeletons_of_the_phrases_and_negations(task: str, skeleton: str) -> None:
    expected = parse_ltl(skeleton)
    if bounded_operators(expected):
        expected = untimed_skeleton(expected)  # the equivalence, read as two implications
    assert untimed_skeleton(parse_ltl(task)) == expected


def _deadlines_dropped(formula: Formula) -> Formula:
    """``formula`` with ``F[a,b]`` read as ``F`` and ``U[a,b]`` as ``U`` (durations kept)."""
    again = _deadlines_dropped
    match formula:
        case BoundedEventually(arg, _):
            return Eventually(again(arg))
        case BoundedUntil(left, right, _):
            return Until(again(left), again(right))
        case BoundedGlobally(arg, interval):
            return BoundedGlobally(again(arg), interval)
        case Not(arg) | Eventually(arg) | Globally(arg):
            return type(formula)(again(arg))
        case And(args) | Or(args):
            return type(formula)(tuple(again(a) for a in args))
        case Implies(left, right) | Equiv(left, right) | Until(left, right):
            return type(formula)(again(left), again(right))
        case Release(left, right) | WeakUntil(left, right) | StrongRelease(left, right):
            return type(formula)(again(left), again(right))
        case _:
            return formula


@settings(max_examples=300)
@given(bounded_formulas(("a", "b", "c"), max_leaves=5), traces())
def test_the_holding_skeleton_keeps_durations_and_implies_the_skeleton(
    formula: Formula, trace: TickTrace
) -> None:
    holding = holding_skeleton(formula)
    assert not bounded_operators(holding)
    held = dense_values(holding, trace, 0.25)
    skeleton = dense_values(untimed_skeleton(formula), trace, 0.25)
    durations = dense_values(_deadlines_dropped(formula), trace, 0.25)
    for t, value in held.items():
        if value:
            assert skeleton[t]
            assert durations[t]


@pytest.mark.parametrize(
    ("task", "holding"),
    [
        ("F G[0,5] a", "F G a"),
        ("F[0,30] dock & F G[0,5] home", "F dock & F G home"),
        ("G(a -> F[0,5] !a)", "G(a -> F !a)"),
        ("!F[0,5] a", "!F a"),
        ("G[2,4] a", "G a"),
    ],
)
def test_holding_skeletons(task: str, holding: str) -> None:
    assert holding_skeleton(parse_ltl(task)) == parse_ltl(holding)
