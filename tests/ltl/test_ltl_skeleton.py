"""The untimed skeleton the planner plans a bounded task on: every run that satisfies the task
satisfies its skeleton (checked with the definition-level dense-time evaluator), and the
skeleton has no bounds."""

from __future__ import annotations

import pytest
from dense_mtl import TickTrace, dense_values
from hypothesis import given, settings
from hypothesis import strategies as st
from strategies import bounded_formulas, formulas

from tlmpc.ltl.ast import Formula, bounded_operators
from tlmpc.ltl.bounds import untimed_skeleton
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
