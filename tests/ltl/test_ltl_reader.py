"""The lark-free LTL reader agrees with the lark parser wherever it answers."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl.ast import Formula
from tlmpc.ltl.lark_parser import parse_ltl as parse_with_lark
from tlmpc.ltl.reader import read_plain_ltl

ROOT = Path(__file__).resolve().parents[2]

Shape = list[tuple[str, object, object, object]]


def shape(formula: Formula) -> Shape:
    """Node kinds, names, constants and spans, pre-order (spans take no part in ==)."""
    out: Shape = []
    for node in formula.walk():
        out.append(
            (
                type(node).__name__,
                getattr(node, "name", None),
                getattr(node, "value", None),
                node.span,
            )
        )
    return out


def lark_or_none(text: str, line: int, col: int) -> Formula | None:
    try:
        return parse_with_lark(text, line=line, col=col)
    except InvalidInputError:
        return None


SPACE = st.sampled_from(["", " ", "  ", "\n", " \n  ", "\t"])
NAMES = st.sampled_from(["a", "b", "r31_13", "Fa", "Ga", "U2", "true_x", "trueish", "_x", "room1"])


@st.composite
def formulas(draw: st.DrawFn, depth: int = 0) -> str:
    """Well-formed formula text in every spelling, with random spaces and parentheses."""
    if depth > 4 or draw(st.integers(0, 3)) == 0:
        leaf = draw(st.one_of(NAMES, st.sampled_from(["true", "false", "1", "0"])))
    else:
        kind = draw(st.sampled_from(["unary", "binary", "chain"]))
        if kind == "unary":
            op = draw(st.sampled_from(["!", "~", "F", "G", "<>", "[]", "FG", "GF", "F G"]))
            gap = draw(SPACE) if op[-1] in "!~>]" else " " + draw(SPACE)
            leaf = op + gap + draw(formulas(depth + 1))
        else:
            ops = {
                "binary": ["U", "R", "W", "M", "V", "->", "=>", "<->", "<=>"],
                "chain": ["&", "&&", "/\\", "|", "||", "\\/"],
            }[kind]
            op = draw(st.sampled_from(ops))
            left, right = draw(formulas(depth + 1)), draw(formulas(depth + 1))
            leaf = f"{left} {draw(SPACE)}{op}{draw(SPACE)} {right}"
    if draw(st.booleans()):
        leaf = "(" + draw(SPACE) + leaf + draw(SPACE) + ")"
    return leaf


@pytest.mark.slow
@settings(max_examples=2 * settings().max_examples)  # 400 in CI
@given(formulas(), st.integers(1, 5), st.integers(1, 9))
def test_reader_equals_lark_on_well_formed_formulas(text: str, line: int, col: int) -> None:
    fast = read_plain_ltl(text, line, col)
    slow = lark_or_none(text, line, col)
    if fast is None:
        return  # left to lark: nothing to compare
    assert slow is not None, text
    assert fast == slow
    assert shape(fast) == shape(slow), text


TOKENS = st.sampled_from(
    [
        "a",
        "b",
        "U",
        "R",
        "F",
        "G",
        "X",
        "N",
        "V",
        "W",
        "M",
        "FX",
        "true",
        "false",
        "1",
        "0",
        "12",
        "(",
        ")",
        "!",
        "~",
        "&",
        "|",
        "->",
        "<->",
        "<>",
        "[]",
        "&&",
        "||",
        '"q"',
        "<",
        "-",
        "/",
        "\\",
        "#",
        " ",
        "\n",
        "é",
        "x1",
    ]
)


@settings(max_examples=600)
@given(st.lists(TOKENS, max_size=12).map(lambda parts: " ".join(parts)))
def test_reader_never_accepts_what_lark_rejects(text: str) -> None:
    fast = read_plain_ltl(text)
    slow = lark_or_none(text, 1, 1)
    if fast is not None:
        assert slow is not None, text
        assert shape(fast) == shape(slow), text


def test_reader_covers_the_shipped_examples_and_printed_formulas() -> None:
    for text in ["F r31_13 & F r12_30", "G (a -> F b) & G F c", "!o1 U (g & F h)"]:
        fast = read_plain_ltl(text)
        assert fast is not None
        assert shape(fast) == shape(parse_with_lark(text))


def test_deep_and_long_formulas_are_left_to_lark() -> None:
    assert read_plain_ltl("(" * 41 + "a" + ")" * 41) is None
    assert read_plain_ltl("F" * 41 + " a") is None
    assert read_plain_ltl("!" * 41 + "a") is None
    assert read_plain_ltl(" & ".join(["a"] * 3000)) is None


def test_parsing_a_plain_formula_imports_no_lark() -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    code = (
        "import sys\n"
        "from tlmpc.ltl import parse_ltl\n"
        "parse_ltl('G (a -> F b) & F c')\n"
        "print(sorted(m for m in sys.modules if m == 'lark' or m.startswith('lark.')))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    )
    assert done.stdout.strip() == "[]"
