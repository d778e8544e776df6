"""Reactive missions: the format, the phrases, and the GR(1) reading of every part.

The reading is checked against Spot: a lasso word satisfies a part exactly when the part's
pieces hold along it (the initial condition on the first letter, invariants on every letter,
recurrences on the loop, and each monitor's deterministic run reading every letter without
getting stuck and taking every acceptance set infinitely often).
"""

from __future__ import annotations

import io
import itertools
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.automata.guards import holds
from tlmpc.base.errors import InvalidInputError
from tlmpc.cli import main
from tlmpc.ltl import parse_ltl, to_text
from tlmpc.ltl.ast import Formula
from tlmpc.mission import load_mission_text
from tlmpc.mission.model import TaskPart
from tlmpc.reactive.fragment import NotGr1, Piece, pieces
from tlmpc.tasks.compiler import NameKinds, compile_phrase

spot = pytest.importorskip("spot")

KINDS = NameKinds(
    regions=frozenset({"a", "b", "dock"}),
    groups=frozenset({"rooms"}),
    sensors=frozenset({"s", "t"}),
    actions=frozenset({"beep"}),
)

MISSION = """\
version: 1
workspace: {{boundary: {{rect: [0, 0, 10, 4]}}}}
regions:
  a: {{rect: [0, 0, 2, 4]}}
  b: {{rect: [8, 0, 10, 4]}}
sensors:
  s: {{column: s_seen}}
  t: null
actions: {{beep: null}}
{extra}robot: {{start: [5, 2]}}
task:
{task}
"""


def _mission(task: list[str], extra: str = "") -> str:
    return MISSION.format(task="\n".join(f"  - {p}" for p in task), extra=extra)


@pytest.mark.parametrize(
    ("phrase", "ltl"),
    [
        ("if you sense s then visit a", "G(s -> F a)"),
        ("If you are sensing s, visit a and b", "G(s -> F a & F b)"),
        ("if you see any of s, t then visit a", "G(s | t -> F a)"),
        ("when s, go to a and stay there while s", "G(s -> F(!s | a)) & G(s & a -> (a W !s))"),
        ("visit a, b infinitely often unless s", "G F(a | s) & G F(b | s)"),
        ("never enter a while all of s, t", "G(s & t & !a -> (!a W !(s & t)))"),
        ("if you sense s then do beep", "G(s -> beep)"),
        ("visit dock", "F dock"),
    ],
)
def test_reactive_phrases_mean_their_formulas(phrase: str, ltl: str) -> None:
    assert compile_phrase(phrase, kinds=KINDS) == parse_ltl(ltl)


@pytest.mark.parametrize(
    ("phrase", "code", "column"),
    [
        ("if you sense a then visit a", "T020", 14),
        ("if you sense s then visit t", "T020", 27),
        ("if you sense s then do a", "T020", 24),
        ("when s, go to a and stay there while t", "T021", 38),
    ],
)
def test_names_of_the_wrong_kind_are_located(phrase: str, code: str, column: int) -> None:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase(phrase, kinds=KINDS, line=3, col=1)
    found = caught.value.diagnostics[0]
    assert (found.code, found.line, found.col) == (code, 3, column)


def test_a_reactive_mission_loads_with_its_bindings() -> None:
    mission = load_mission_text(
        _mission(["if you sense s then visit a"], extra='assumptions: ["G F !s"]\n'),
        "m.yaml",
    )
    assert mission.reactive is not None
    assert mission.reactive.sensor_names == ("s", "t")
    assert mission.reactive.sensors[0].column == "s_seen"
    assert mission.reactive.actions == ("beep",)
    assert [to_text(p.formula) for p in mission.reactive.assumptions] == ["G F !s"]
    assert mission.to_json()["reactive"]["sensors"] == {"s": {"column": "s_seen"}, "t": {}}


def test_a_mission_without_sensors_writes_no_reactive_object() -> None:
    text = _mission(["visit a"]).replace("sensors:\n  s: {column: s_seen}\n  t: null\n", "")
    text = text.replace("actions: {beep: null}\n", "")
    assert "reactive" not in load_mission_text(text, "m.yaml").to_json()


@pytest.mark.parametrize(
    ("extra", "task", "code"),
    [
        ('assumptions: ["G F beep"]\n', ["visit a"], "Q101"),
        ('assumptions: ["G F nothing"]\n', ["visit a"], "L010"),
        ("", ["if you sense s then visit nowhere"], "L010"),
    ],
)
def test_bad_reactive_missions_are_diagnosed(extra: str, task: list[str], code: str) -> None:
    with pytest.raises(InvalidInputError) as caught:
        load_mission_text(_mission(task, extra), "m.yaml")
    assert code in {d.code for d in caught.value.diagnostics}


def test_a_name_declared_twice_is_s013() -> None:
    text = _mission(["visit a"]).replace("  t: null\n", "  a: null\n")
    with pytest.raises(InvalidInputError) as caught:
        load_mission_text(text, "m.yaml")
    assert [d.code for d in caught.value.diagnostics] == ["S013"]


def test_persistence_is_outside_the_fragment_with_a_located_hint() -> None:
    part = TaskPart(text="F G a", formula=parse_ltl("F G a"), line=7, col=5)
    with pytest.raises(NotGr1) as caught:
        pieces(part, "sys", "m.yaml")
    found = caught.value.diagnostic
    assert (found.code, found.file, found.line, found.col) == ("Q102", "m.yaml", 7, 5)
    assert "G F" in (found.hint or "")


# --- the reading against Spot -------------------------------------------------------------

APS = ("p", "q", "r")
props = st.sampled_from(APS)


def _propositional(depth: int) -> st.SearchStrategy[str]:
    leaf = props | props.map(lambda p: f"!{p}")
    if depth == 0:
        return leaf
    inner = _propositional(depth - 1)
    return leaf | st.tuples(inner, st.sampled_from(["&", "|", "->"]), inner).map(
        lambda t: f"({t[0]} {t[1]} {t[2]})"
    )


def _formula() -> st.SearchStrategy[list[str]]:
    c = _propositional(1)
    patterns = st.one_of(
        c,
        c.map(lambda x: f"G {x}"),
        c.map(lambda x: f"G F {x}"),
        st.tuples(c, c).map(lambda t: f"G({t[0]} -> F {t[1]})"),
        st.tuples(c, c, c).map(lambda t: f"G({t[0]} -> ({t[1]} W {t[2]}))"),
        st.tuples(c, c).map(lambda t: f"F({t[0]} & F {t[1]})"),
        st.tuples(c, c).map(lambda t: f"({t[0]} U {t[1]})"),
        st.tuples(c, c).map(lambda t: f"G({t[0]} -> G {t[1]})"),
        c.map(lambda x: f"F G {x}"),
        st.tuples(c, c).map(lambda t: f"G({t[0]} | F {t[1]}) | F {t[0]}"),
    )
    return st.lists(patterns, min_size=1, max_size=3)


letters = st.lists(st.frozensets(props), min_size=1, max_size=4)


def _run_accepts(piece: Piece, prefix: list[frozenset[str]], cycle: list[frozenset[str]]) -> bool:
    """The piece's constraints on the lasso word prefix cycle^omega."""
    formula = piece.formula
    if piece.kind == "init":
        return holds(formula, (prefix + cycle)[0])
    if piece.kind == "invariant":
        return all(holds(formula, letter) for letter in prefix + cycle)
    if piece.kind == "recurrence":
        return any(holds(formula, letter) for letter in cycle)
    automaton = piece.automaton
    assert automaton is not None
    state = automaton.initial
    # Run the deterministic automaton; after the prefix, go round the cycle until a state at
    # the cycle's start repeats: the marks seen from then on are the ones seen infinitely often.
    seen: dict[int, int] = {}
    marks_per_lap: list[set[int]] = []
    for letter in prefix:
        step = [e for e in automaton.edges if e.src == state and holds(e.guard, letter)]
        if not step:
            return False
        state = step[0].dst
    while state not in seen:
        seen[state] = len(marks_per_lap)
        lap: set[int] = set()
        for letter in cycle:
            step = [e for e in automaton.edges if e.src == state and holds(e.guard, letter)]
            if not step:
                return False
            lap |= step[0].marks
            state = step[0].dst
        marks_per_lap.append(lap)
    recurring = set().union(*marks_per_lap[seen[state] :])
    return recurring >= set(range(automaton.num_acc))


def _spot_accepts(
    formula: Formula, prefix: list[frozenset[str]], cycle: list[frozenset[str]]
) -> bool:
    def letter(values: frozenset[str]) -> str:
        return " & ".join(ap if ap in values else f"!{ap}" for ap in APS)

    word = "; ".join(letter(v) for v in prefix)
    word = (word + "; " if word else "") + "cycle{" + "; ".join(letter(v) for v in cycle) + "}"
    automaton = spot.translate(spot.formula(to_text(formula)))
    return bool(automaton.intersects(spot.parse_word(word).as_automaton()))


@settings(max_examples=150, deadline=None)
@given(_formula(), st.lists(st.frozensets(props), max_size=3), letters)
def test_the_gr1_reading_is_exact(
    conjuncts: list[str], prefix: list[frozenset[str]], cycle: list[frozenset[str]]
) -> None:
    refused = []
    for text in conjuncts:
        try:
            pieces(TaskPart(text=text, formula=parse_ltl(text), line=1, col=1), "sys")
        except NotGr1:
            refused.append(text)
    # only persistence, and the disjunction tlmpc translates with a guess, are refused
    assert all(t.startswith("F G") or "| F" in t for t in refused)
    text = " & ".join(f"({c})" for c in conjuncts)
    formula = parse_ltl(text)
    part = TaskPart(text=text, formula=formula, line=1, col=1)
    if refused:
        with pytest.raises(NotGr1):
            pieces(part, "sys")
        return
    found = pieces(part, "sys")
    assert all(_run_accepts(p, prefix, cycle) for p in found) == _spot_accepts(
        formula, prefix, cycle
    )


def test_the_subset_construction_determinises_a_guessing_safety_automaton() -> None:
    # G(p | q) & (G p | G q) has no deterministic translation here; it is safety, so the
    # subset construction makes one
    text = "G p | G q"
    part = TaskPart(text=text, formula=parse_ltl(text), line=1, col=1)
    (piece,) = pieces(part, "sys")
    assert piece.kind == "monitor"
    assert piece.automaton is not None
    for bits in itertools.product([False, True], repeat=2):
        letter = frozenset(ap for ap, bit in zip(("p", "q"), bits, strict=True) if bit)
        for state in range(piece.automaton.num_states):
            out = [e for e in piece.automaton.edges if e.src == state and holds(e.guard, letter)]
            assert len(out) <= 1


def test_a_time_bound_in_a_reactive_mission_is_refused_at_its_part(tmp_path: Path) -> None:
    # the game has no clocks: refused where the bound is written, with a hint that fits
    path = tmp_path / "m.yaml"
    path.write_text(_mission(["visit a", "visit b within 30 s"]))
    err = io.StringIO()
    code = main(["check", str(path)], out=io.StringIO(), err=err)
    assert code == 1
    err_text = err.getvalue()
    line = path.read_text().splitlines().index("  - visit b within 30 s") + 1
    assert err_text.startswith(f"{path}:{line}:5: error[L045]: a reactive mission cannot take")
    assert "compile plans a bounded task" not in err_text
