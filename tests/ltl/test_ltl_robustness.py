"""LTL parser robustness and printer/rewrite details: no input gives a traceback."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from strategies import formulas

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl import parse_ltl, simplify, to_text
from tlmpc.ltl.ast import And, Eventually, Formula, Implies, Not, Prop, Until

_PIECES = st.sampled_from(
    [*'ab()!&|-><[]~"/\\ \n\t01', "U", "F", "G", "X", "R", "W", "M", "true", "p_1", "é", "\x00"]
)


def _check(text: str) -> None:
    try:
        formula = parse_ltl(text, file="m.yaml", line=5, col=9)
    except InvalidInputError as exc:
        diagnostics = exc.diagnostics
    else:
        assert parse_ltl(to_text(formula)) == formula
        return
    for diagnostic in diagnostics:
        assert diagnostic.code.startswith("L")
        assert diagnostic.file == "m.yaml"
        assert diagnostic.line is not None
        assert diagnostic.line >= 5
        assert diagnostic.col is not None
        assert diagnostic.col >= 1
        assert diagnostic.hint


@given(st.one_of(st.text(max_size=40), st.lists(_PIECES, max_size=30).map("".join)))
def test_any_text_gives_a_formula_or_diagnostics(text: str) -> None:
    _check(text)


@pytest.mark.parametrize(
    "text",
    [
        "(" * 10_000 + "a" + ")" * 10_000,
        "!" * 10_000 + "a",
        "F" * 10_000 + " a",
        "F " * 10_000 + "a",
        "[]" * 5_000 + "a",
        "a -> " * 5_000 + "a",
        "(" * 10_000,
        ")" * 10_000,
    ],
)
def test_deep_nesting_is_refused_not_crashed(text: str) -> None:
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl(text)
    assert caught.value.diagnostics[0].code in {"L003", "L005"}


def test_long_flat_chains_are_fine() -> None:
    formula = parse_ltl(" & ".join(f"p{i}" for i in range(5_000)))
    assert isinstance(formula, And)
    assert len(formula.args) == 5_000


def test_multiline_positions() -> None:
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl("F a &\n  G $", file="m.yaml", line=10, col=7)
    diagnostic = caught.value.diagnostics[0]
    assert (diagnostic.code, diagnostic.line, diagnostic.col) == ("L001", 11, 5)


def test_spans_cover_binary_nodes() -> None:
    formula = parse_ltl("a U (b & c)", line=2, col=3)
    assert isinstance(formula, Until)
    assert formula.span is not None
    assert (formula.span.line, formula.span.col) == (2, 3)
    assert isinstance(formula.right, And)
    second = formula.right.args[1]
    assert isinstance(second, Prop)
    assert second.span is not None
    assert second.span.col == 3 + 9


def test_hints_name_what_was_expected() -> None:
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl("a & & b")
    assert "operand" in (caught.value.diagnostics[0].hint or "")
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl("(a b)")
    hint = caught.value.diagnostics[0].hint or ""
    assert "binary operator" in hint
    assert "')'" in hint


@pytest.mark.parametrize(
    ("formula", "text"),
    [
        (And((Prop("a"), And((Prop("b"), Prop("c"))))), "a & (b & c)"),
        (Implies(Implies(Prop("a"), Prop("b")), Prop("c")), "(a -> b) -> c"),
        (Until(Until(Prop("a"), Prop("b")), Prop("c")), "(a U b) U c"),
        (Not(Until(Prop("a"), Prop("b"))), "!(a U b)"),
        (Eventually(Not(Prop("a"))), "F !a"),
        (Prop("room 1"), '"room 1"'),
    ],
)
def test_printer_parenthesises_only_where_needed(formula: Formula, text: str) -> None:
    assert to_text(formula) == text
    assert parse_ltl(text) == formula


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("a & true", "a"),
        ("a | true", "true"),
        ("a & false | b", "b"),
        ("!!a", "a"),
        ("F F a", "F a"),
        ("G G a", "G a"),
        ("F true", "true"),
        ("a & (b & a)", "a & b"),
    ],
)
def test_simplify_folds_constants(text: str, expected: str) -> None:
    assert simplify(parse_ltl(text)) == parse_ltl(expected)


@given(formulas())
def test_simplify_is_idempotent_and_printable(formula: Formula) -> None:
    once = simplify(formula)
    assert simplify(once) == once
    assert parse_ltl(to_text(once)) == once
