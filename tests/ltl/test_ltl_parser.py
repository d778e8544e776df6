"""The LTL language: operators, precedence, spellings, positions, errors."""

from __future__ import annotations

import pytest
from hypothesis import example, given
from lasso_ltl import holds
from strategies import formulas, lassos

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl import is_cosafe, is_safety, nnf, parse_ltl, to_spin, to_text
from tlmpc.ltl.ast import (
    And,
    Const,
    Equiv,
    Eventually,
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

a, b, c = Prop("a"), Prop("b"), Prop("c")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("a & b | c", Or((And((a, b)), c))),
        ("a | b & c", Or((a, And((b, c))))),
        ("a -> b -> c", Implies(a, Implies(b, c))),
        ("a <-> b -> c", Equiv(a, Implies(b, c))),
        # Spot: `%right OP_IMPLIES OP_EQUIV`, one level, right-associative.
        ("a -> b <-> c", Implies(a, Equiv(b, c))),
        ("a <-> b <-> c", Equiv(a, Equiv(b, c))),
        ("(a <-> b) <-> c", Equiv(Equiv(a, b), c)),
        ("a => b <=> c", Implies(a, Equiv(b, c))),
        ("a -> b | c & d", Implies(a, Or((b, And((c, Prop("d"))))))),
        ("a U b & c", And((Until(a, b), c))),
        ("a U b -> c", Implies(Until(a, b), c)),
        ("G a U b", Until(Globally(a), b)),
        ("a U !b R c", Until(a, Release(Not(b), c))),
        ("!F G !a", Not(Eventually(Globally(Not(a))))),
        ("FG a", Eventually(Globally(a))),
        ("a | b | c", Or((a, b, c))),
        ("(a | b) | c", Or((Or((a, b)), c))),
        ("a & b & c", And((a, b, c))),
        ('"room 1" | a', Or((Prop("room 1"), a))),
        ("p1 & room_3 & o1 & GFa", And((Prop("p1"), Prop("room_3"), Prop("o1"), Prop("GFa")))),
        ("a U b U c", Until(a, Until(b, c))),
        ("a & b U c", And((a, Until(b, c)))),
        ("F a U b", Until(Eventually(a), b)),
        ("!a U b", Until(Not(a), b)),
        ("a R b", Release(a, b)),
        ("a V b", Release(a, b)),
        ("a W b", WeakUntil(a, b)),
        ("a M b", StrongRelease(a, b)),
        ("GF a", Globally(Eventually(a))),
        ("[]<> a && <>[] b", And((Globally(Eventually(a)), Eventually(Globally(b))))),
        ("~a || b", Or((Not(a), b))),
        ("a /\\ b \\/ c", Or((And((a, b)), c))),
        ("a & (b & c)", And((a, And((b, c))))),
        ("true & false", And((Const(True), Const(False)))),
        ("1 | 0", Or((Const(True), Const(False)))),
    ],
)
def test_precedence_and_spellings(text: str, expected: object) -> None:
    assert parse_ltl(text) == expected


def test_paper_formula_round_trips_and_prints_readably() -> None:
    text = "F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))"
    assert to_text(parse_ltl(text)) == text


def test_spans_are_shifted_into_the_file() -> None:
    formula = parse_ltl("F  goal", file="m.yaml", line=7, col=10)
    assert isinstance(formula, Eventually)
    assert isinstance(formula.arg, Prop)
    assert formula.arg.span is not None
    assert (formula.arg.span.line, formula.arg.span.col) == (7, 13)


@pytest.mark.parametrize(
    ("text", "cols"),
    [
        ("GF a", [1, 2]),
        ("b & FGF a", [5, 6, 7]),
        ("GF[0,40] a", [1, 2]),
        ("GGF[2,4] a", [1, 2, 3]),
        ("<> a", [1]),
        ("[] a", [1]),
    ],
)
def test_each_letter_of_an_operator_chain_is_located_at_itself(text: str, cols: list[int]) -> None:
    node = parse_ltl(text, file="m.yaml", line=7, col=10)
    if isinstance(node, And):
        node = node.args[1]
    found = []
    while not isinstance(node, Prop):
        assert node.span is not None
        found.append(node.span.col)
        assert (node.span.line, node.span.end_col) == (7, 10 + len(text))
        node = node.children()[0]
    assert found == [10 + c - 1 for c in cols]


@pytest.mark.parametrize("text", ["X p1", "G X a", "F(a & X b)", "N a"])
def test_next_is_rejected_with_an_explanation(text: str) -> None:
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl(text, file="m.yaml", line=3, col=6)
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == "L004"
    assert "continuous time" in (diagnostic.hint or "")
    assert diagnostic.line == 3


@pytest.mark.parametrize(
    ("text", "code", "col"),
    [
        ("a & ", "L002", 5),
        ("a $ b", "L001", 3),
        ("", "L002", 1),
        ("a b", "L003", 3),
        (")", "L003", 1),
        ("(" * 500 + "a" + ")" * 500, "L005", 1),
        ("a U " * 2000 + "b", "L005", 1),
    ],
)
def test_syntax_errors_have_positions(text: str, code: str, col: int) -> None:
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl(text)
    assert caught.value.diagnostics[0].code == code
    assert caught.value.diagnostics[0].col == col


@given(formulas())
def test_print_then_parse_is_the_identity(formula: object) -> None:
    assert parse_ltl(to_text(formula)) == formula  # type: ignore[arg-type]


@given(formulas(), lassos())
# a negated F and G, where their duals and the operators with the negation pushed in differ
@example(Not(Eventually(Prop("a"))), ([frozenset({"a"}), frozenset()], 0))
@example(Not(Globally(Prop("a"))), ([frozenset(), frozenset({"a"})], 1))
def test_nnf_preserves_meaning(formula: object, lasso: tuple[list[frozenset[str]], int]) -> None:
    word, loop = lasso
    normal = nnf(formula)  # type: ignore[arg-type]
    assert holds(normal, word, loop) == holds(formula, word, loop)  # type: ignore[arg-type]
    for node in normal.walk():
        assert not isinstance(node, Implies | Equiv)
        if isinstance(node, Not):
            assert isinstance(node.arg, Prop)


@pytest.mark.parametrize(
    ("text", "cosafe", "safety"),
    [
        ("F a & F b", True, False),
        ("G !o", False, True),
        ("a U b", True, False),
        ("a W b", False, True),
        ("G F a", False, False),
        ("!(a U b)", False, True),
        ("a & !b", True, True),
        ("F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))", True, False),
    ],
)
def test_syntactic_classes(text: str, cosafe: bool, safety: bool) -> None:
    formula = parse_ltl(text)
    assert is_cosafe(formula) is cosafe
    assert is_safety(formula) is safety


def test_spin_syntax_expands_weak_until_and_strong_release() -> None:
    assert to_spin(parse_ltl("a W b")) == "((b) V ((a) || (b)))"
    assert to_spin(parse_ltl("a M b")) == "((b) U ((a) && (b)))"
    assert to_spin(parse_ltl("G(a -> F b)")) == "[](((a) -> (<>(b))))"


def test_brackets_inside_a_quoted_name_are_not_nesting() -> None:
    # a quoted name may hold any character: 401 brackets in it are a name, not 401 levels
    name = "(" * 401 + '\\"' + ")" * 3
    formula = parse_ltl(f'F "{name}"')
    assert formula == parse_ltl(f'F("{name}")')
    with pytest.raises(InvalidInputError) as caught:  # and the limit still holds outside
        parse_ltl("F " + "(" * 401 + f'"{name}"' + ")" * 401)
    assert caught.value.diagnostics[0].code == "L005"
