"""The readers follow their source tools' grammars and readings."""

from __future__ import annotations

import itertools

import pytest
from game_oracle import evaluate

from tlmpc.base.errors import UsageError
from tlmpc.synth.readers.gr1c import parse_gr1c
from tlmpc.synth.readers.slugsin import parse_slugsin
from tlmpc.synth.readers.tlsf import parse_tlsf
from tlmpc.synth.solver import Game, solve
from tlmpc.synth.spec import Atom, Binary, Nary, Not, Part


def test_gr1c_and_or_share_a_level_and_group_left() -> None:
    spec = parse_gr1c("SYS: a b c;\nSYSINIT: a | b & !c -> a <-> b;\n")
    (part,) = spec.parts
    formula = part.formula
    # ((((a | b) & !c) -> a) <-> b)
    assert isinstance(formula, Binary)
    assert formula.op == "<->"
    implication = formula.left
    assert isinstance(implication, Binary)
    assert implication.op == "->"
    conjunction = implication.left
    assert isinstance(conjunction, Nary)
    assert conjunction.op == "and"
    disjunction, negation = conjunction.args
    assert isinstance(disjunction, Nary)
    assert disjunction.op == "or"
    assert isinstance(negation, Not)


def test_gr1c_and_box_on_one_line_starts_a_new_goal() -> None:
    spec = parse_gr1c("ENV: x;\nSYS: y;\nENVGOAL: []<> x & !y\n& []<> x & y;\n")
    goals = spec.select("env", "liveness")
    assert [g.text for g in goals] == ["x & !y", "x & y"]


def test_slugs_memory_buffers_share_formulas() -> None:
    spec = parse_slugsin("[INPUT]\na\n[OUTPUT]\nb\n[SYS_TRANS]\n$ 2 ^ a b' & ? 0 ! a\n")
    (part,) = spec.parts
    formula = part.formula
    assert isinstance(formula, Nary)
    assert formula.op == "and"
    shared, negated = formula.args
    assert isinstance(shared, Nary)
    assert shared.op == "xor"
    assert shared.args[1] == Atom("b", True)
    assert isinstance(negated, Not)


def _tlsf(semantics: str, body: str) -> str:
    return (
        f'INFO {{ TITLE: "t" SEMANTICS: {semantics} TARGET: Mealy }}\nGLOBAL {{}}\n'
        f"MAIN {{\nINPUTS {{ r; }}\nOUTPUTS {{ g; }}\n{body}\n}}\n"
    )


def test_slugs_buffer_size_is_bounded_by_its_line() -> None:
    """``$ N`` with N far beyond the line's words is refused before any room for N formulas
    is set aside."""
    import tracemalloc

    text = "[INPUT]\nx\n[OUTPUT]\ny\n[SYS_TRANS]\n$ 100000000 y\n"
    tracemalloc.start()
    try:
        with pytest.raises(UsageError) as caught:
            parse_slugsin(text, file="big.slugsin")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    found = caught.value.diagnostics[0]
    assert (found.code, found.line, found.col) == ("Q030", 6, 1)
    assert "ends early" in found.message
    assert peak < 10_000_000


def test_tlsf_sections_become_parts_of_the_right_player() -> None:
    spec = parse_tlsf(
        _tlsf(
            "Mealy,Strict",
            "INITIALLY { !r; }\nPRESET { !g; }\nREQUIRE { g -> X !r; }\n"
            "ASSERT { X g <-> r; }\nASSUME { G F r; }\nGUARANTEE { G F g; }",
        )
    )
    kinds = [(p.owner, p.kind) for p in spec.parts]
    assert kinds == [
        ("env", "init"),
        ("sys", "init"),
        ("env", "safety"),
        ("sys", "safety"),
        ("env", "liveness"),
        ("sys", "liveness"),
    ]
    # a G in ASSUME is environment safety, a G in GUARANTEE system safety (each where the game
    # decides the file's meaning: see test_tlsf_meaning)
    assumed = parse_tlsf(_tlsf("Mealy,Strict", "ASSUME { G F r && G (r -> X !r); }"))
    assert [(p.owner, p.kind) for p in assumed.parts] == [("env", "liveness"), ("env", "safety")]
    unconditioned = parse_tlsf(
        _tlsf("Mealy,Strict", "PRESET { !g; }\nASSERT { X g <-> r; }\nGUARANTEE { G (r -> g); }")
    )
    assert [(p.owner, p.kind) for p in unconditioned.parts] == [
        ("sys", "init"),
        ("sys", "safety"),
        ("sys", "safety"),
    ]
    # g follows r one step late, so the first r finds g low and breaks G (r -> g):
    # unrealizable
    assert not solve(Game.build(unconditioned)).realizable


def test_tlsf_mealy_lets_the_system_see_the_inputs_of_the_step() -> None:
    # g must equal r in every step: realizable only because the system answers after r (Mealy)
    mealy = parse_tlsf(_tlsf("Mealy", "GUARANTEE { G (g <-> r); }"))
    assert solve(Game.build(mealy)).realizable
    # g must equal the next r: the system would have to predict the input
    predict = parse_tlsf(_tlsf("Mealy", "GUARANTEE { G (g <-> X r); }"))
    assert not solve(Game.build(predict)).realizable


def test_tlsf_strict_safety_ends_when_the_environment_breaks_its_own() -> None:
    # the environment promises r stays low; the system must keep g equal to the previous r
    # and never raise g: only an environment that breaks REQUIRE could force g up
    spec = parse_tlsf(
        _tlsf(
            "Mealy,Strict",
            "INITIALLY { !r; }\nPRESET { !g; }\nREQUIRE { !X r; }\nASSERT { X g <-> r; !g; }",
        )
    )
    assert solve(Game.build(spec)).realizable
    unguarded = parse_tlsf(
        _tlsf("Mealy,Strict", "INITIALLY { !r; }\nPRESET { !g; }\nASSERT { X g <-> r; !g; }")
    )
    assert not solve(Game.build(unguarded)).realizable


def test_tlsf_without_main_or_semantics_says_what_is_missing() -> None:
    main = "MAIN { INPUTS { r; } OUTPUTS { g; } REQUIRE { r; } ASSERT { g; } }\n"
    cases = {
        "": "neither an INFO nor a MAIN section",
        "/* nothing */\n": "neither an INFO nor a MAIN section",
        "INFO { SEMANTICS: Mealy,Strict }\n": "no MAIN section",
        main: "SEMANTICS is missing",
        'INFO { TITLE: "t" }\n' + main: "SEMANTICS is missing",
    }
    for text, message in cases.items():
        with pytest.raises(UsageError) as caught:
            parse_tlsf(text, file="t.tlsf")
        found = caught.value.diagnostics[0]
        assert found.code == "Q041", text
        assert message in found.message, (text, found.message)


@pytest.mark.parametrize("name", ["true", "false", "X", "G", "F", "U", "W", "R"])
def test_tlsf_signal_named_like_a_keyword_is_refused_at_its_declaration(name: str) -> None:
    """A formula reads such a name as the operator or constant, never as the signal: a
    `true` input would vanish from ``G (true -> g)``."""
    text = (
        'INFO { TITLE: "t" SEMANTICS: Mealy TARGET: Mealy }\n'
        f"MAIN {{\nINPUTS {{ r; {name}; }}\nOUTPUTS {{ g; }}\nGUARANTEE {{ G F g; }}\n}}\n"
    )
    with pytest.raises(UsageError) as caught:
        parse_tlsf(text, file="t.tlsf")
    found = caught.value.diagnostics[0]
    assert (found.code, found.line, found.col) == ("Q041", 3, 13)
    assert "keyword" in found.message


def test_gr1c_one_side_init() -> None:
    """gr1c's ONE_SIDE_INIT: a SYSINIT alone needs one winning state; an ENVINIT alone needs
    every state it allows to win (y is frozen, and only y = True wins)."""
    frozen = "ENV: x;\nSYS: y;\nSYSTRANS: [](y' <-> y);\nSYSGOAL: []<> y;\n"
    sys_side = parse_gr1c(frozen + "SYSINIT: x & y;\n", init_mode="one_side")
    assert solve(Game.build(sys_side)).realizable
    env_side = parse_gr1c(frozen + "ENVINIT: x | y;\n", init_mode="one_side")
    assert not solve(Game.build(env_side)).realizable
    env_side_ok = parse_gr1c(frozen + "ENVINIT: y;\n", init_mode="one_side")
    assert solve(Game.build(env_side_ok)).realizable


def _same_function(left: Part, right: Part) -> bool:
    """Whether two parts' formulas agree on every valuation of r, g and their next values."""
    names = [("r", False), ("g", False), ("r", True), ("g", True)]
    for bits in itertools.product([False, True], repeat=len(names)):
        values = dict(zip(names, bits, strict=True))
        now = {name: v for (name, primed), v in values.items() if not primed}
        nxt = {name: v for (name, primed), v in values.items() if primed}
        if evaluate(left.formula, now, nxt) != evaluate(right.formula, now, nxt):
            return False
    return True


@pytest.mark.parametrize(
    ("section", "formula", "text"),
    [
        ("ASSERT", "(g && r) || (!g && !r) -> X(!g)", "(g && r) || (!g && !r) -> X(!g)"),
        ("ASSERT", "G ((g))", "((g))"),
        ("REQUIRE", "(!r) -> X (r)", "(!r) -> X (r)"),
        ("REQUIRE", "X !r || g", "X !r || g"),
        ("ASSERT", "!g && X (g || r)", "!g && X (g || r)"),
        ("GUARANTEE", "G F ((g || r) && (g || !r))", "((g || r) && (g || !r))"),
        ("GUARANTEE", "(G (g -> X r)) && G F (g)", "(g -> X r)"),
        ("ASSUME", "G F r && (G F (!r))", "r"),
        ("PRESET", "((g) && (r || !g))", "((g) && (r || !g))"),
    ],
)
def test_tlsf_part_is_its_whole_conjunct_as_written(section: str, formula: str, text: str) -> None:
    """A part's location is where its conjunct starts and its text the conjunct as written
    (parentheses included): read back in the same section, the text is the same formula."""
    body = f"{section} {{ {formula}; }}"
    source = _tlsf("Mealy,Strict", body)
    spec = parse_tlsf(source)
    first = spec.parts[0]
    assert first.text == text
    line = source.splitlines()[first.location.line - 1]
    assert line[first.location.col - 1 :].startswith(text)
    for part in spec.parts:
        again = part.text if part.kind != "liveness" else f"G F {part.text}"
        if section in ("ASSUME", "GUARANTEE") and part.kind == "safety":
            again = f"G {part.text}"
        (reread,) = parse_tlsf(_tlsf("Mealy,Strict", f"{section} {{ {again}; }}")).parts
        assert _same_function(part, reread), (part.text, again)
