"""Task phrases: noise words, the paper's full sentence, positions, and no tracebacks."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl import parse_ltl, to_text
from tlmpc.ltl.ast import Prop
from tlmpc.tasks import compile_phrase, compile_phrases

PAPER = "F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))"


def test_the_papers_sentence_word_for_word() -> None:
    sentence = (
        "Visit area p2 then area p3 then area p4 and, finally, "
        "return to region p1 while avoiding areas p2 and p3"
    )
    assert to_text(compile_phrase(sentence)) == PAPER


@pytest.mark.parametrize(
    ("phrase", "ltl"),
    [
        ("visit area", "F area"),  # a region may be called `area`
        ("visit area, b", "F area & F b"),
        ("visit room a and room b", "F a & F b"),
        ("avoid region o1, o2", "G !o1 & G !o2"),
        ("stay in region", "F G region"),
        ("go to a then b", "F(a & F b)"),
        ("reach a", "F a"),
        ("visit a, then b, and then c", "F(a & F(b & F c))"),
        ("visit a then b.", "F(a & F b)"),
        ("Whenever alarm visit exit", "G(alarm -> F exit)"),
        ("remain at dock", "F G dock"),
        ("visit a then b then c while avoiding d", "F(a & F(b & F c)) & G !d"),
        ("avoid a and b until c", "(!a & !b) U c"),
        ("patrol a", "G F a"),
        ("visit a, b infinitely often", "G F a & G F b"),
    ],
)
def test_more_phrase_forms(phrase: str, ltl: str) -> None:
    assert compile_phrase(phrase) == parse_ltl(ltl)


def test_avoiding_a_region_never_visited_is_global_after_a_return_too() -> None:
    plain = compile_phrase("visit a then b while avoiding c")
    ret = compile_phrase("visit a then return to b while avoiding c")
    assert plain == parse_ltl("F(a & F b) & G !c")
    assert ret == parse_ltl("F(a & F b) & G !c")


def test_name_spans_point_into_the_file() -> None:
    formula = compile_phrase("visit area kitchen then lab", file="m.yaml", line=3, col=7)
    spans = {n.name: n.span for n in formula.walk() if isinstance(n, Prop)}
    assert spans["kitchen"] is not None
    assert (spans["kitchen"].line, spans["kitchen"].col) == (3, 18)
    assert spans["lab"] is not None
    assert spans["lab"].col == 7 + len("visit area kitchen then ")


def test_names_on_a_second_line_keep_their_line() -> None:
    formula = compile_phrase("visit a then\n  b", line=4, col=5)
    spans = {n.name: n.span for n in formula.walk() if isinstance(n, Prop)}
    assert spans["b"] is not None
    assert (spans["b"].line, spans["b"].col) == (5, 3)


@pytest.mark.parametrize("phrase", ["", "   ", "visit", "visit a then", "avoid", "go", "visit a b"])
def test_incomplete_phrases_are_diagnosed(phrase: str) -> None:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrases([phrase], file="m.yaml", positions=[(8, 5)])
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == "T001"
    assert diagnostic.line == 8
    assert "visit A then B then C" in (diagnostic.hint or "")


def test_did_you_mean_for_a_misspelt_keyword() -> None:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase("patrl a, b")
    assert "did you mean 'patrol'" in (caught.value.diagnostics[0].hint or "")


_WORDS = st.sampled_from(
    [
        "visit",
        "then",
        "and",
        ",",
        "avoid",
        "avoiding",
        "while",
        "return",
        "to",
        "all",
        "any",
        "rooms",
        "a",
        "b",
        "area",
        "until",
        "patrol",
        "stay",
        "in",
        "whenever",
        "infinitely",
        "often",
        "é",
        "!",
        "\n",
        "finally",
    ]
)


@given(st.one_of(st.text(max_size=30), st.lists(_WORDS, max_size=10).map(" ".join)))
def test_any_phrase_gives_a_formula_or_diagnostics(phrase: str) -> None:
    try:
        formula = compile_phrases([phrase], groups={"rooms": ["a", "b"]}, positions=[(2, 3)])
    except InvalidInputError as exc:
        diagnostics = exc.diagnostics
    else:
        assert parse_ltl(to_text(formula)) == formula
        return
    assert all(d.code.startswith("T") and d.line is not None for d in diagnostics)
