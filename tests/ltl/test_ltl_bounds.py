"""Time bounds in the LTL language: parsing, printing, diagnostics, rewrites."""

from __future__ import annotations

import math

import pytest
from dense_mtl import TickTrace, dense_values
from hypothesis import given
from hypothesis import strategies as st
from strategies import bounded_formulas

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl.ast import (
    BoundedEventually,
    BoundedGlobally,
    BoundedUntil,
    Eventually,
    Formula,
    Globally,
    Interval,
    Not,
    Prop,
)
from tlmpc.ltl.parser import parse_ltl
from tlmpc.ltl.printer import to_text
from tlmpc.ltl.transform import is_cosafe, is_safety, nnf, simplify

a, b = Prop("a"), Prop("b")


@pytest.mark.parametrize(
    ("text", "tree"),
    [
        ("F[0,5] a", BoundedEventually(a, Interval(0, 5))),
        ("G[2, inf] a", BoundedGlobally(a, Interval(2, math.inf))),
        ("a U[0.5,1e3] b", BoundedUntil(a, b, Interval(0.5, 1000))),
        ("GF[0,40] a", Globally(BoundedEventually(a, Interval(0, 40)))),
        ("F G[0,5] a", Eventually(BoundedGlobally(a, Interval(0, 5)))),
        ("!F[1,1] a", Not(BoundedEventually(a, Interval(1, 1)))),
        ("F[0,infinity] a", BoundedEventually(a, Interval(0, math.inf))),
    ],
)
def test_parse(text: str, tree: Formula) -> None:
    assert parse_ltl(text) == tree
    assert parse_ltl(to_text(tree)) == tree


@pytest.mark.parametrize("gap", ["\n", "\r\n", "\n    ", " \n\t"])
def test_a_bound_may_be_written_over_lines(gap: str) -> None:
    assert parse_ltl(f"G (a -> F[0,{gap}5] b)") == parse_ltl("G (a -> F[0,5] b)")
    assert parse_ltl(f"a U[{gap}1 ,{gap}2{gap}] b") == parse_ltl("a U[1,2] b")
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl(f"F a & G[3,{gap}2] b", file="m.yaml", line=4, col=1)
    (diagnostic,) = caught.value.diagnostics
    assert (diagnostic.code, diagnostic.line, diagnostic.col) == ("L041", 4, 8)
    assert "\n" not in diagnostic.message, "the bound shown on one line"


def test_bounded_operators_bind_like_their_namesakes() -> None:
    assert parse_ltl("F[0,1] a U[0,2] b & c") == parse_ltl("((F[0,1] a) U[0,2] b) & c")
    assert parse_ltl("a U[0,1] b U c") == parse_ltl("a U[0,1] (b U c)")


@pytest.mark.parametrize(
    ("text", "code", "col"),
    [
        ("F[5,1] a", "L041", 2),
        ("F[-1,2] a", "L042", 2),
        ("F[0,-2] a", "L042", 2),
        ("F[0,-inf] a", "L042", 2),
        ("G[-Infinity,2] a", "L042", 2),
        ("G[nan,2] a", "L043", 2),
        ("F[inf,inf] a", "L043", 2),
        ("F[1] a", "L040", 2),
        ("F[1,2,3] a", "L040", 2),
        ("F[0,5s] a", "L040", 2),
        ("F[0,1e309] a", "L040", 2),
        ("G[2e308,inf] a", "L040", 2),
        ("a R[0,1] b", "L044", 3),
        ("a W[0,1] b", "L044", 3),
        ("F a & G[3,2] b", "L041", 8),
    ],
)
def test_bad_bounds_are_located(text: str, code: str, col: int) -> None:
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl(text, file="m.yaml", line=4, col=1)
    (diagnostic,) = caught.value.diagnostics
    assert (diagnostic.code, diagnostic.line, diagnostic.col) == (code, 4, col)
    assert diagnostic.hint


@given(bounded_formulas(("a", "b", "c"), max_leaves=8))
def test_printing_reads_back(formula: Formula) -> None:
    assert parse_ltl(to_text(formula)) == formula


@given(st.floats(0, 1e12, allow_nan=False), st.floats(0, 1e12, allow_nan=False))
def test_any_bound_prints_exactly(x: float, y: float) -> None:
    low, high = sorted((x, y))
    formula = BoundedEventually(a, Interval(low, high))
    assert parse_ltl(to_text(formula)) == formula


@st.composite
def stays(draw: st.DrawFn) -> TickTrace:
    breaks = [0]
    for gap in draw(st.lists(st.sampled_from([2, 4]), max_size=3)):
        breaks.append(breaks[-1] + gap)
    count = 2 * len(breaks) - 1
    letters = st.frozensets(st.sampled_from(["a", "b", "c"]))
    return TickTrace(tuple(breaks), tuple(draw(st.lists(letters, min_size=count, max_size=count))))


@given(bounded_formulas(("a", "b", "c"), max_leaves=5), stays())
def test_nnf_and_simplify_keep_the_meaning(formula: Formula, trace: TickTrace) -> None:
    expected = dense_values(formula, trace, 0.25)
    assert dense_values(nnf(formula), trace, 0.25) == expected
    assert dense_values(simplify(formula), trace, 0.25) == expected


def test_bounds_are_in_neither_planner_class() -> None:
    assert not is_cosafe(parse_ltl("F[0,5] a"))
    assert not is_safety(parse_ltl("G[0,5] a"))
    assert nnf(parse_ltl("!(a U[0,1] b)")) == Not(BoundedUntil(a, b, Interval(0, 1)))


@pytest.mark.parametrize(
    ("text", "normal"),
    [
        ("!F[0,1] a", "G[0,1] !a"),
        ("!G[0,1] a", "F[0,1] !a"),
        ("F[0,1] a -> b", "G[0,1] !a | b"),
        ("!G[1,2] (a & F[0,1] b)", "F[1,2] (!a | G[0,1] !b)"),
    ],
)
def test_nnf_dualises_the_bounds(text: str, normal: str) -> None:
    formula = parse_ltl(text)
    assert nnf(formula) == parse_ltl(normal)
    trace = TickTrace((0, 2, 6), tuple(frozenset(s) for s in ("a", "", "b", "ab", "")))
    assert dense_values(nnf(formula), trace, 0.25) == dense_values(formula, trace, 0.25)
