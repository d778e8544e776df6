"""The fast phrase reader agrees with the Earley parser of ``tasks.lark`` wherever it answers.

The oracle is lark's Earley parser on the grammar file (the definition of the language):
whenever :func:`parse_plain` returns a tree, Earley must return the same tree (same rules,
same names at the same lines and columns).  Phrases are drawn from the whole grammar, with
names chosen to trip a hand-written reader: names that begin with a keyword (``visitor``,
``tox``, ``andy``), the nouns (``room``), the halves of two-word keywords (``go``, ``one``,
``come``), odd spacing, case and punctuation, and also as free token soup.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.tasks.compiler import _from_lark, _parser
from tlmpc.tasks.phrases import KEYWORDS, Node, Word, parse_plain

ROOT = Path(__file__).resolve().parents[2]

PLAIN_NAMES = [
    "a",
    "b",
    "p1",
    "r_2",
    "kitchen",
    "Hall",
    "_x",
    "gate7",
    "area",
    "rooms",
    "go",
    "one",
    "come",
    "of",
    "back",
    "F",
    "true",
]
TRICKY_NAMES = [
    "visitor",
    "tox",
    "andy",
    "allx",
    "anyway",
    "inbox",
    "attic",
    "thenx",
    "finally_",
    "avoid_x",
    "stayed",
    "returned",
    "whilex",
    "office",
    "background",
    "often2",
    "never_",
    "patrolman",
    "alwaysx",
    "untilx",
    "eventuallyx",
    "Visit2",
    "dock",
    "door",
    "ifx",
    "youth",
    "seen",
    "whence",
    "therefore",
    "unlessx",
    "entrance",
    "sensed",
    "andes",
    "reacher",
    "visitors",
    "tomorrow",
    "offset",
    "backyard",
    "atleast",
]
KEYWORD_WORDS = [
    "visit",
    "go to",
    "reach",
    "then",
    "and",
    "finally",
    "avoid",
    "avoiding",
    "never",
    "until",
    "patrol",
    "stay",
    "remain",
    "in",
    "at",
    "always",
    "eventually",
    "whenever",
    "return to",
    "come back to",
    "to",
    "while",
    "all",
    "any",
    "one of",
    "infinitely",
    "often",
    ",",
    ".",
    "area",
    "room",
    "if you sense",
    "when",
    "there",
    "unless",
    "enter",
    "do",
    "any of",
    "all of",
]


def _shape(tree: Node | Word) -> Any:
    if isinstance(tree, Word):
        return ("word", str(tree), tree.line, tree.column)
    return (tree.data, tuple(_shape(c) for c in tree.children))


def _earley(phrase: str) -> Any:
    from lark.exceptions import LarkError

    try:
        return _shape(_from_lark(_parser().parse(phrase)))
    except LarkError:
        return None


def _agree(phrase: str) -> bool:
    """Check the reader against Earley; True when the reader answered."""
    plain = parse_plain(phrase)
    if plain is None:
        return False
    assert _shape(plain) == _earley(phrase), phrase
    return True


names = st.sampled_from(PLAIN_NAMES + TRICKY_NAMES)
spaces = st.sampled_from([" ", " ", " ", "  ", "\t", "\n", " \n  "])


@st.composite
def name_lists(draw: st.DrawFn) -> str:
    count = draw(st.integers(1, 4))
    text = draw(st.sampled_from(["", "area ", "rooms ", "region "])) + draw(names)
    for _ in range(count - 1):
        text += draw(st.sampled_from([", ", " and ", ", and ", ",", " AND "])) + draw(names)
    return text


@st.composite
def phrases(draw: st.DrawFn) -> str:
    visit = draw(st.sampled_from(["visit", "Visit", "go to", "reach", "go  to", "VISIT"]))
    then = draw(
        st.sampled_from(
            [
                " then ",
                ", then ",
                " and then ",
                ", and, finally, ",
                " then, finally ",
                " finally ",
                ",then ",
                " andthen ",
            ]
        )
    )
    avoiding = draw(st.sampled_from(["", " while avoiding ", ", while avoiding "]))
    kind = draw(st.integers(0, 11))
    if kind == 0:
        steps = [draw(name_lists()) for _ in range(draw(st.integers(1, 4)))]
        later = [draw(st.sampled_from(["", visit + " ", "all "])) + s for s in steps[1:]]
        text = f"{visit} " + then.join([steps[0], *later])
        if draw(st.booleans()):
            text += then + draw(st.sampled_from(["return to ", "come back to ", "return  to "]))
            text += draw(names)
        if avoiding:
            text += avoiding + draw(name_lists())
    elif kind == 1:
        text = f"{visit} all {draw(names)}" + (
            then + draw(name_lists()) if draw(st.booleans()) else ""
        )
    elif kind == 2:
        text = f"{visit} {draw(st.sampled_from(['any', 'one of', 'one  of']))} {draw(names)}"
    elif kind == 3:
        text = f"{visit} {draw(name_lists())} infinitely often"
    elif kind == 4:
        text = f"{draw(st.sampled_from(['avoid', 'never visit', 'Never go to']))} "
        text += draw(name_lists())
    elif kind == 5:
        text = f"avoid {draw(name_lists())} until {draw(names)}"
    elif kind == 6:
        text = f"patrol {draw(name_lists())}"
    elif kind == 7:
        text = draw(
            st.sampled_from(
                [
                    "stay in ",
                    "eventually stay at ",
                    "remain in ",
                    "always stay in ",
                    "always remain at ",
                ]
            )
        ) + draw(names)
    elif kind == 8:
        text = f"whenever {draw(names)}{draw(st.sampled_from([',', '', ' ,']))} "
        text += f"{visit} {draw(names)}"
    elif kind == 9:
        text = f"{visit} {draw(name_lists())}"
    else:
        text = f"{visit} {draw(name_lists())}{avoiding or ' while avoiding '}{draw(name_lists())}"
    text = text.replace(" ", draw(spaces), draw(st.integers(0, 2)))
    return text + draw(st.sampled_from(["", ".", " .", ". ", "!", " ,"]))


@given(phrases())
def test_reader_agrees_with_earley_on_grammar_phrases(phrase: str) -> None:
    _agree(phrase)


@given(
    st.lists(st.sampled_from(KEYWORD_WORDS + PLAIN_NAMES + TRICKY_NAMES), min_size=1, max_size=9),
    spaces,
)
def test_reader_agrees_with_earley_on_token_soup(words: list[str], space: str) -> None:
    _agree(space.join(words))


@pytest.mark.parametrize(
    "phrase",
    [
        "visit a",
        "Visit p2, then p3, then p4 and, finally, return to p1 while avoiding p2 and p3",
        "visit a, b and c then go to d",
        "visit all rooms then d",
        "visit any rooms",
        "go to one of rooms",
        "visit a infinitely often",
        "avoid a until b",
        "never visit a",
        "patrol a, b",
        "eventually stay in a",
        "always stay in a",
        "whenever a, visit b",
        "visit area p2 then rooms p3 and p4.",
        "visit a\nthen b",
        "visit a then come back to b",
    ],
)
def test_plain_phrases_are_read_without_earley(phrase: str) -> None:
    assert _agree(phrase)


def _spec_phrases() -> list[str]:
    found: list[str] = []
    for spec in sorted((ROOT / "specs").glob("*.yaml")):
        data = yaml.safe_load(spec.read_text(encoding="utf-8"))
        if isinstance(data, dict) and isinstance(data.get("task"), list):
            found.extend(p for p in data["task"] if isinstance(p, str))
    return found


def test_shipped_phrases_agree_and_most_are_plain() -> None:
    found = _spec_phrases()
    assert found
    plain = sum(_agree(p) for p in found)
    assert plain >= 0.9 * len(found)


def _names(tree: Node | Word) -> list[str]:
    if isinstance(tree, Word):
        return [str(tree)]
    return [name for child in tree.children for name in _names(child)]


#: Held-out phrases whose names begin with a keyword, and the names a reader sees in them: a
#: keyword is a whole word (docs/task-phrases.md, "How phrases are read").
WHOLE_WORD_NAMES = [
    ("visit dock then visitor", ["dock", "visitor"]),
    ("visit a then reacher", ["a", "reacher"]),
    ("visit a, then visitors then b", ["a", "visitors", "b"]),
    ("visit a then visitb", ["a", "visitb"]),
    ("visit allx", ["allx"]),
    ("visit a, andy", ["a", "andy"]),
    ("visit a,andes", ["a", "andes"]),
    ("patrol dock, andes", ["dock", "andes"]),
    ("visit lab while avoiding dock, andes", ["lab", "dock", "andes"]),
    ("avoid a, andes until b", ["a", "andes", "b"]),
    ("visit a then return tofu_stand", None),  # `return to` is two words
    ("go tox", None),
    ("visit a andthen b", None),
    ("visit a thenfinally b", None),
    ("visitor", None),
]


def _earley_names(phrase: str) -> list[str] | None:
    """The names the Earley parser reads in ``phrase``, or None when it refuses it."""
    from lark.exceptions import LarkError

    try:
        return _names(_from_lark(_parser().parse(phrase)))
    except LarkError:
        return None


@pytest.mark.parametrize(("phrase", "expected"), WHOLE_WORD_NAMES)
def test_names_that_begin_with_a_keyword_are_whole_names(
    phrase: str, expected: list[str] | None
) -> None:
    assert _earley_names(phrase) == expected
    plain = parse_plain(phrase)
    assert (None if plain is None else _names(plain)) == expected
    if expected is not None:
        assert _agree(phrase)


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        ("if you sense s then visit a, andes", ["s", "a", "andes"]),
        ("if you sense dock then do doors", ["dock", "doors"]),
        ("never enter andes while seen", ["andes", "seen"]),
        (
            "when sensed, go to therefore and stay there while sensed",
            ["sensed", "therefore", "sensed"],
        ),
        ("if you sense any offset then visit a", None),  # not `any of` + `fset`
        ("stay in a for at leastx 5 s", None),
    ],
)
def test_reactive_and_timed_names_that_begin_with_a_keyword_are_whole_names(
    phrase: str, expected: list[str] | None
) -> None:
    assert _earley_names(phrase) == expected


def test_keywords_are_the_grammars() -> None:
    grammar = (ROOT / "tlmpc" / "tasks" / "tasks.lark").read_text(encoding="utf-8")
    match = re.search(r"NAME: /\(\?!\(([a-z|]+)\)", grammar)
    assert match is not None
    assert set(match.group(1).split("|")) == KEYWORDS
