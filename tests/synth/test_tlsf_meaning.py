"""A TLSF file's verdict is the verdict of its LTL meaning, or the file is refused (Q047).

The meaning is TLSF's (syfco's ``merge``, the formulas as written, an empty conjunction true):
``INITIALLY -> (PRESET && ((G REQUIRE && ASSUME) -> (G ASSERT && GUARANTEE)))`` under plain
``Mealy``, ``INITIALLY -> (PRESET && (ASSERT W !REQUIRE) && ((G REQUIRE && ASSUME) ->
GUARANTEE))`` under ``Mealy,Strict``.  Spot's game solver decides it (Mealy: the system answers
the inputs of the same step), independently of the GR(1) game tlmpc builds.  Random small
GR(1)-shaped files must get Spot's verdict, or Q047 where the game would decide something else.
"""

from __future__ import annotations

import random

import pytest

from tlmpc.base.errors import UsageError
from tlmpc.synth.readers.tlsf import parse_tlsf
from tlmpc.synth.solver import Game, solve

spot = pytest.importorskip("spot")

INPUTS = ("x0", "x1")
OUTPUTS = ("y0", "y1")


def spot_realizable(formula: str) -> bool:
    """Spot's verdict on an LTL formula over INPUTS and OUTPUTS (Mealy)."""
    arena = spot.ltl_to_game(spot.formula(formula), list(OUTPUTS), spot.synthesis_info())
    return bool(spot.solve_game(arena))


def boolean(rng: random.Random, atoms: list[str], depth: int = 2) -> str:
    """A fully parenthesised Boolean formula (the same text in TLSF and in Spot)."""
    if depth == 0 or rng.random() < 0.3:
        return rng.choice([*atoms, "true", "false"]) if rng.random() < 0.9 else rng.choice(atoms)
    op = rng.choice(["!", "&&", "||", "->", "<->"])
    if op == "!":
        return f"(!{boolean(rng, atoms, depth - 1)})"
    return f"({boolean(rng, atoms, depth - 1)} {op} {boolean(rng, atoms, depth - 1)})"


def random_file(rng: random.Random) -> tuple[str, str]:
    """A random GR(1)-shaped TLSF file and its LTL meaning."""
    now = list(INPUTS + OUTPUTS)
    next_inputs = [f"X {x}" for x in INPUTS]
    next_all = next_inputs + [f"X {y}" for y in OUTPUTS]

    def some(make: object, most: int) -> list[str]:
        assert callable(make)
        return [make() for _ in range(rng.randint(0, most))]

    def step(atoms: list[str]) -> str:
        formula = boolean(rng, atoms)
        # a G on top of a REQUIRE or ASSERT formula changes what ASSERT W !REQUIRE means
        return f"G {formula}" if rng.random() < 0.15 else formula

    def temporal(safety_atoms: list[str]) -> str:
        if rng.random() < 0.5:
            return f"G F {boolean(rng, now)}"
        return f"G {boolean(rng, safety_atoms)}"

    sections = {
        "INITIALLY": some(lambda: boolean(rng, list(INPUTS)), 1),
        "PRESET": some(lambda: boolean(rng, now), 1),
        "REQUIRE": some(lambda: step(now + next_inputs), 2),
        "ASSERT": some(lambda: step(now + next_all), 2),
        "ASSUME": some(lambda: temporal(now + next_inputs), 2),
        "GUARANTEE": some(lambda: temporal(now + next_all), 2),
    }
    strict = rng.random() < 0.5
    body = "\n".join(
        f"{name} {{ {' '.join(f + ';' for f in formulas)} }}"
        for name, formulas in sections.items()
        if formulas
    )
    text = (
        f"INFO {{ SEMANTICS: {'Mealy,Strict' if strict else 'Mealy'} }}\n"
        f"MAIN {{\nINPUTS {{ {' '.join(x + ';' for x in INPUTS)} }}\n"
        f"OUTPUTS {{ {' '.join(y + ';' for y in OUTPUTS)} }}\n{body}\n}}\n"
    )
    return text, meaning(sections, strict)


def meaning(sections: dict[str, list[str]], strict: bool) -> str:
    """TLSF's LTL meaning of the sections (syfco's merge)."""

    def conj(name: str) -> str:
        return " && ".join(f"({f})" for f in sections[name]) or "true"

    premise = f"(G ({conj('REQUIRE')}) && {conj('ASSUME')})"
    if strict:
        weak = f"(({conj('ASSERT')}) W (!({conj('REQUIRE')})))"
        body = f"({conj('PRESET')}) && {weak} && ({premise} -> ({conj('GUARANTEE')}))"
    else:
        body = f"({conj('PRESET')}) && ({premise} -> (G ({conj('ASSERT')}) && {conj('GUARANTEE')}))"
    return f"({conj('INITIALLY')}) -> ({body})"


def verdict(text: str) -> bool | str:
    """tlmpc's verdict on a TLSF text, or the code it refuses it with."""
    try:
        spec = parse_tlsf(text, file="random.tlsf")
    except UsageError as refused:
        return refused.diagnostics[0].code
    return solve(Game.build(spec), keep_layers=False).realizable


def test_random_files_get_the_verdict_of_their_meaning_or_q047() -> None:
    rng = random.Random(20240611)
    answered = refused = 0
    for _ in range(1000):
        text, formula = random_file(rng)
        found = verdict(text)
        if isinstance(found, str):
            assert found == "Q047", text
            refused += 1
            continue
        assert found == spot_realizable(formula), f"{text}\nmeaning: {formula}"
        answered += 1
    # neither side vacuous: the exact fragment is answered, the rest refused
    assert answered >= 250
    assert refused >= 100


SECTIONS = ("INITIALLY", "PRESET", "REQUIRE", "ASSERT", "ASSUME", "GUARANTEE")


def _file(semantics: str, sections: dict[str, list[str]]) -> str:
    body = " ".join(
        f"{name} {{ {' '.join(f + ';' for f in sections[name])} }}" for name in sections
    )
    head = f"INFO {{ SEMANTICS: {semantics} }}\nMAIN {{\nINPUTS {{ x; }}\nOUTPUTS {{ y; }}\n"
    return f"{head}{body}\n}}\n"


@pytest.mark.parametrize(
    ("semantics", "sections", "at"),
    [
        # the system never raises y: the assumption G F y is false and the file holds
        # (Spot: realizable), while the game asks for !x in every step
        ("Mealy", {"ASSUME": ["G F y"], "ASSERT": ["!x"]}, "!x"),
        ("Mealy", {"ASSUME": ["G F y"], "GUARANTEE": ["G !x"]}, "!x"),
        ("Mealy,Strict", {"ASSUME": ["G F y"], "GUARANTEE": ["G !x"]}, "!x"),
        # ASSERT holds until REQUIRE (there is none) is broken, whatever ASSUME's G says:
        # unrealizable; the game would let y break the assumption and free the system
        ("Mealy,Strict", {"ASSUME": ["G !y"], "ASSERT": ["x"]}, "!y"),
        # (G x) W y is not x W y
        ("Mealy,Strict", {"REQUIRE": ["!y"], "ASSERT": ["G x"]}, "G x"),
        ("Mealy,Strict", {"REQUIRE": ["G !y"], "ASSERT": ["x"]}, "G !y"),
    ],
)
def test_an_implication_the_game_does_not_decide_is_refused(
    semantics: str, sections: dict[str, list[str]], at: str
) -> None:
    """Each file's meaning is not what the GR(1) game decides: refused, located at the part
    read differently (line 5 holds the sections)."""
    text = _file(semantics, sections)
    with pytest.raises(UsageError) as caught:
        parse_tlsf(text, file="t.tlsf")
    found = caught.value.diagnostics[0]
    body = text.splitlines()[4]
    assert (found.code, found.line, found.col) == ("Q047", 5, body.index(at) + 1)
    assert found.hint


@pytest.mark.parametrize(
    ("semantics", "sections"),
    [
        ("Mealy", {"ASSUME": ["G F x", "G !y"], "GUARANTEE": ["G F y"]}),
        ("Mealy", {"ASSERT": ["X y <-> x"], "GUARANTEE": ["G F y", "G (y -> x)"]}),
        ("Mealy,Strict", {"REQUIRE": ["y -> X !x"], "ASSERT": ["X y <-> x"], "ASSUME": ["G F x"]}),
        ("Mealy,Strict", {"ASSUME": ["G (y -> X x)", "G F x"], "GUARANTEE": ["G F y"]}),
        ("Mealy,Strict", {"GUARANTEE": ["G (y <-> x)", "G F y"]}),
        ("Mealy,Strict", {"ASSERT": ["G (y <-> X x)"]}),
    ],
)
def test_the_exact_fragment_gets_the_verdict_of_its_meaning(
    semantics: str, sections: dict[str, list[str]]
) -> None:
    found = verdict(_file(semantics, sections))
    assert isinstance(found, bool), found
    formula = meaning({name: sections.get(name, []) for name in SECTIONS}, "Strict" in semantics)
    arena = spot.ltl_to_game(spot.formula(formula), ["y"], spot.synthesis_info())
    assert found == bool(spot.solve_game(arena)), formula
