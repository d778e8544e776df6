"""HOA/JSON/DOT formats, the automaton command, sizes and speed on the benchmark formulas."""

from __future__ import annotations

import argparse
import io
import itertools
import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from test_automata_props import formulas

from tlmpc.automata import (
    Automaton,
    automaton_from_json,
    automaton_to_json,
    degeneralize,
    guard_holds,
    parse_hoa,
    successor_table,
    to_dot,
    to_hoa,
    translate,
)
from tlmpc.base.errors import InvalidInputError
from tlmpc.commands import automaton as command
from tlmpc.io.schema_check import validation_errors
from tlmpc.ltl import parse_ltl
from tlmpc.ltl.ast import Formula

FORMULAS = Path(__file__).with_name("formulas.txt")


def benchmark() -> list[tuple[str, int | None, str]]:
    rows = []
    for line in FORMULAS.read_text(encoding="utf-8").splitlines():
        if line.strip() and not line.startswith("#"):
            name, spin, _ms, text = line.split("\t")
            rows.append((name, int(spin) if spin.isdigit() else None, text))
    return rows


def signature(aut: Automaton) -> set[tuple[int, int, frozenset[int], tuple[bool, ...]]]:
    """Edges with guards as truth tables (structural equality up to guard syntax)."""
    letters = [
        frozenset(p for p, bit in zip(aut.aps, bits, strict=True) if bit)
        for bits in itertools.product((False, True), repeat=len(aut.aps))
    ]
    return {
        (e.src, e.dst, e.marks, tuple(guard_holds(e.guard, x) for x in letters)) for e in aut.edges
    }


def same(a: Automaton, b: Automaton) -> None:
    assert (a.num_states, a.initial, a.num_acc, a.aps, a.state_based) == (
        b.num_states,
        b.initial,
        b.num_acc,
        b.aps,
        b.state_based,
    )
    assert signature(a) == signature(b)


@settings(max_examples=60)
@given(formulas())
def test_hoa_and_json_round_trip(formula: Formula) -> None:
    for aut in (translate(formula), degeneralize(translate(formula))):
        same(parse_hoa(to_hoa(aut)), aut)
        document = automaton_to_json(aut)
        assert validation_errors(document, "automaton") == []
        same(automaton_from_json(json.loads(json.dumps(document))), aut)
        assert to_dot(aut).startswith("digraph")


def test_hoa_header() -> None:
    text = to_hoa(translate(parse_ltl("G F a & G F b")))
    assert text.startswith("HOA: v1\n")
    assert 'tool: "tlmpc"' in text
    assert "acc-name: generalized-Buchi 2" in text
    assert "Acceptance: 2 Inf(0)&Inf(1)" in text
    assert "trans-acc" in text
    assert "tlmpc-ltl:" in text
    assert text.rstrip().endswith("--END--")
    ba = to_hoa(degeneralize(translate(parse_ltl("G F a & G F b"))))
    assert "acc-name: Buchi" in ba
    assert "state-acc" in ba


def test_parse_spot_style_hoa() -> None:
    text = """HOA: v1
name: "GFa" States: 2 Start: 0 AP: 1 "a"
acc-name: Buchi Acceptance: 1 Inf(0)
properties: trans-labels explicit-labels state-acc /* a comment */
--BODY--
State: 0 {0}
[0] 0
[!0] 1
State: 1
[t] 1
[0 & t] 0
--END--
"""
    aut = parse_hoa(text)
    assert aut.num_states == 2
    assert aut.aps == ("a",)
    assert all(e.marks == frozenset({0}) for e in aut.edges if e.src == 0)


BODY = "--BODY--\nState: 0\n[0] 0 {0}\n--END--\n"


@pytest.mark.parametrize(
    "text",
    [
        "HOA: v1\nStates: 1\nStart: 0\nAP: 0\nAcceptance: 1 Inf(0)\n" + BODY,
        'HOA: v1\nStates: 1\nStart: 0\nAP: 1 "a"\nAcceptance: 1 Fin(0)\n' + BODY,
        'HOA: v1\nStates: 1\nStart: 3\nAP: 1 "a"\nAcceptance: 1 Inf(0)\n' + BODY,
        'HOA: v1\nStates: 1\nStart: 0\nAP: 1 "a"\nAcceptance: 1 Inf(0)\n'
        "--BODY--\nState: 0\n[0] 4 {0}\n--END--\n",
        'HOA: v1\nStates: 1\nStart: 0\nAP: 1 "a"\nAcceptance: 1 Inf(0)\n'
        "--BODY--\nState: 0\n[0] 0 {2}\n--END--\n",
    ],
)
def test_unsupported_hoa_gives_b003(text: str) -> None:
    with pytest.raises(InvalidInputError) as info:
        parse_hoa(text)
    assert {d.code for d in info.value.diagnostics} == {"B003"}


@pytest.mark.parametrize(
    "text",
    [
        "",
        "HOA: v2\n--BODY--\n--END--\n",
        "HOA: v1\nAcceptance: 1 Inf(0)\n--BODY--\nState: 0\n[0 &] 0\n--END--\n",
    ],
)
def test_bad_hoa_gives_b_codes(text: str) -> None:
    with pytest.raises(InvalidInputError) as info:
        parse_hoa(text)
    assert all(d.code.startswith("B") for d in info.value.diagnostics)


@pytest.mark.parametrize(("name", "spin_states", "text"), benchmark())
def test_benchmark_sizes(name: str, spin_states: int | None, text: str) -> None:
    # Sizes only: speed is shown by bench/bench_automata.py, never asserted here (the suite
    # must pass on a loaded machine).
    formula = parse_ltl(text)
    tgba = translate(formula)
    ba = degeneralize(tgba)
    if spin_states is not None:
        assert ba.num_states <= spin_states, (name, ba.num_states, spin_states)
    if name.startswith("patrol"):
        assert tgba.num_states == 1
    if name.startswith("cover"):
        assert tgba.num_states == 2 ** int(name[5:])
    if name == "paper-fkp05":
        assert ba.num_states <= 5


def test_successor_table() -> None:
    aut = translate(parse_ltl("F (a & F b)"))
    letters = [(), ("a",), ("b",), ("a", "z")]
    table = successor_table(aut, letters)
    assert len(table) == 4
    assert all(len(row) == aut.num_states for row in table)
    for i, letter in enumerate(letters):
        for q in range(aut.num_states):
            expected = {
                (e.dst, sum(1 << m for m in e.marks))
                for e in aut.edges
                if e.src == q and guard_holds(e.guard, letter)
            }
            assert set(table[i][q]) == expected
            assert len(table[i][q]) == len(set(table[i][q]))


def run_command(*argv: str) -> tuple[int, str, str]:
    parser = argparse.ArgumentParser()
    command.add_arguments(parser)
    out, err = io.StringIO(), io.StringIO()
    code = command.run(parser.parse_args(list(argv)), out, err)
    return code, out.getvalue(), err.getvalue()


def test_command_formats() -> None:
    code, out, _ = run_command("G F a & G F b")
    assert code == 0
    assert out.startswith("HOA: v1")
    assert parse_hoa(out).num_states == 1
    code, out, _ = run_command("F a & F b", "--format", "json", "--ba")
    document = json.loads(out)
    assert code == 0
    assert validation_errors(document, "automaton") == []
    assert document["acceptance"]["state_based"] is True
    code, out, _ = run_command("F a", "--format", "dot")
    assert code == 0
    assert out.startswith("digraph")
    code, out, _ = run_command("F a & F b & F c", "--stats")
    assert code == 0
    assert "states: 8" in out
    code, out, _ = run_command("F a & F b & F c", "--stats", "--json")
    assert json.loads(out)["result"]["stats"]["states"] == 8


def test_command_bad_formula() -> None:
    with pytest.raises(InvalidInputError) as info:
        run_command("F (a &")
    assert info.value.diagnostics[0].code.startswith("L")


def test_state_names_read_back_as_formulas_over_the_same_names() -> None:
    # names that need quotes: a constant's word, an operator, empty, a space, a quote
    text = 'F "true" & G F "U" & F "" & F "a b" & F "q\\"x" & G(plain -> F !"true")'
    formula = parse_ltl(text)
    automaton = translate(formula)
    for name in automaton.state_names:
        assert parse_ltl(name).props() <= formula.props(), name
    assert any('"a b"' in name for name in automaton.state_names)
