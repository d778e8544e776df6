"""`GFa` is one proposition; an unknown one that is operators fused with a known name gets a
hint naming the formula meant (`G F a`)."""

from __future__ import annotations

import io
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from tlmpc.cli import main
from tlmpc.ltl.ast import Eventually, Globally, Prop
from tlmpc.ltl.fused import UNARY_OPERATORS, fused_operators
from tlmpc.ltl.parser import parse_ltl

names = st.from_regex(r"[a-z_][a-z0-9_]{0,6}", fullmatch=True)
prefixes = st.text(alphabet="FG", min_size=1, max_size=4)


@given(prefixes, names, st.sets(names, max_size=4))
def test_the_suggestion_is_the_name_split_into_operators_and_a_known_name(
    prefix: str, name: str, others: set[str]
) -> None:
    known = {name} | others
    fused = prefix + name
    suggestion = fused_operators(fused, known)
    assert suggestion is not None
    words = suggestion.split(" ")
    assert "".join(words) == fused
    assert words[-1] in known
    assert all(w in UNARY_OPERATORS for w in words[:-1])
    # the suggestion parses as those operators applied to the proposition, outermost first
    node = parse_ltl(suggestion)
    for word in words[:-1]:
        assert isinstance(node, Eventually if word == "F" else Globally)
        assert isinstance(node, Eventually | Globally)
        node = node.arg
    assert node == Prop(words[-1])


@given(prefixes, names)
def test_no_suggestion_for_a_known_name_or_without_a_known_rest(prefix: str, name: str) -> None:
    assert fused_operators(prefix + name, {prefix + name, name}) is None
    assert fused_operators(prefix + name, set()) is None
    assert fused_operators(name, {name}) is None


def test_check_hints_at_g_f_a(tmp_path: Path) -> None:
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nworkspace:\n  boundary: {rect: [0, 0, 10, 10]}\nregions:\n"
        "  a: {rect: [1, 1, 2, 2]}\nrobot: {start: [5, 5]}\nltl: GFa\n"
    )
    err = io.StringIO()
    assert main(["check", str(mission)], io.StringIO(), err) == 1
    text = err.getvalue()
    assert f"{mission}:7:6: error[L010]: unknown region 'GFa'" in text
    assert "did you mean `G F a`?" in text
