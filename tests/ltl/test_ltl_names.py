"""Proposition names: the printer quotes what the parser would not read back as the same name,
and the parser refuses operator keywords as bare names (L030)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from strategies import formulas

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl import parse_ltl, to_text
from tlmpc.ltl.ast import Eventually, Formula, Globally, Prop, Until

# Any text may name a region: keywords, operator letters, digits, spaces, quotes,
# backslashes, newlines, non-ASCII letters and the empty name.
NAMES = st.lists(st.text(max_size=6), min_size=1, max_size=4, unique=True)


@pytest.mark.slow
@given(NAMES.flatmap(lambda names: formulas(tuple(names), max_leaves=8)))
def test_print_then_parse_is_the_identity_for_any_names(formula: Formula) -> None:
    assert parse_ltl(to_text(formula)) == formula


@pytest.mark.parametrize(
    "name",
    [
        "true",
        "false",
        "U",
        "R",
        "W",
        "M",
        "V",
        "F",
        "G",
        "X",
        "N",
        "FG",
        "GFX",
        "1",
        "0",
        "ä",
        "Straße",
        "a b",
        'a"b',
        "a\\b",
        "a\nb",
        "",
        "2x",
        "x-y",
    ],
)
def test_names_that_are_not_bare_identifiers_are_quoted(name: str) -> None:
    text = to_text(Globally(Prop(name)))
    assert text.startswith('G "'), text
    assert parse_ltl(text) == Globally(Prop(name))


@pytest.mark.parametrize("name", ["a", "room_1", "_x", "GFa", "Fx", "trueish", "U1", "Vx"])
def test_plain_identifiers_stay_bare(name: str) -> None:
    assert to_text(Eventually(Prop(name))) == f"F {name}"


@pytest.mark.parametrize(
    ("text", "cols"),
    [
        ("U U U", [1, 5]),
        ("a U V", [5]),
        ("p & W", [5]),
        ("M", [1]),
        ("F R", [3]),
        ("(R -> a) & G !W", [2, 15]),
    ],
)
def test_operator_keywords_are_not_names(text: str, cols: list[int]) -> None:
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl(text, file="m.yaml", line=4, col=10)
    diagnostics = caught.value.diagnostics
    assert [d.code for d in diagnostics] == ["L030"] * len(cols)
    assert [d.col for d in diagnostics] == [10 + c - 1 for c in cols]
    assert all(d.line == 4 and d.file == "m.yaml" for d in diagnostics)
    assert all(d.hint and "double quotes" in d.hint for d in diagnostics)
    # quoting names a proposition, never a mission's region (S008 refuses keyword names)
    assert all(d.hint and "a mission cannot name a region" in d.hint for d in diagnostics)


def test_quoted_keywords_are_names() -> None:
    assert parse_ltl('"U" U "U"') == Until(Prop("U"), Prop("U"))
    assert parse_ltl('"a\\"b"') == Prop('a"b')
    assert parse_ltl('"a\\\\b"') == Prop("a\\b")
    assert parse_ltl('"a\\nb"') == Prop("a\nb")


@given(
    st.text(st.characters(blacklist_characters='"\\\n'), max_size=5),
    st.characters(blacklist_characters='"\\n\n'),
    st.integers(0, 2),
)
def test_an_unknown_escape_in_a_quoted_name_is_refused_at_its_backslash(
    before: str, letter: str, pairs: int
) -> None:
    # `"a\tb"` read as `atb` would name another region than the one meant; escaped
    # backslashes before it do not hide it, an escaped backslash before the letter does
    text = f'F "{before}{chr(92) * 2 * pairs}\\{letter}"'
    with pytest.raises(InvalidInputError) as caught:
        parse_ltl(text)
    found = caught.value.diagnostics[0]
    assert (found.code, found.line, found.col) == ("L031", 1, 4 + len(before) + 2 * pairs)
    kept = f'F "{before}{chr(92) * 2 * (pairs + 1)}{letter}"'
    assert parse_ltl(kept) == Eventually(Prop(f"{before}{chr(92) * (pairs + 1)}{letter}"))
