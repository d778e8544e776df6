"""Spot as the oracle: tlmpc's TGBA is language-equivalent to Spot's on every benchmark family
(Dwyer, Etessami–Holzmann, Somenzi–Bloem, robotics, random Next-free formulas), sizes are
compared, and translations restricted to a map's letters agree with Spot on those letters.

What is compared: tlmpc's :func:`translate` over the full alphabet (every valuation of the
propositions) against ``spot.translate(f, "TGBA", "Small", "High")``, both transition-based
generalized Büchi; tlmpc's automaton goes through its HOA export and Spot's HOA reader.  In CI
(the ``ci`` hypothesis profile) fewer random formulas are drawn; never none.
"""

from __future__ import annotations

import json
import warnings
from typing import Any

import pytest
from ci_oracles import import_oracle
from hypothesis import given, settings
from hypothesis import strategies as st

with warnings.catch_warnings():
    # Spot's SWIG modules warn on import (builtin types without __module__); the project
    # turns warnings into errors, which must not happen inside Spot's extension code.
    warnings.simplefilter("ignore", DeprecationWarning)
    spot = import_oracle("spot")
    from spot_families import families, to_tlmpc
from strategies import formulas

from tlmpc.automata import (
    automaton_from_json,
    automaton_to_json,
    degeneralize,
    parse_hoa,
    to_hoa,
    translate,
)
from tlmpc.ltl import parse_ltl, to_text
from tlmpc.ltl.ast import Formula

#: Random formulas per run: half the hypothesis example budget of the active profile.
RANDOM_COUNT = max(20, settings().max_examples // 2)
#: Formulas over more propositions are compared by the benchmark only (Spot's own translation
#: and equivalence check take seconds there: twelve `G F p_i` take Spot about 10 s).
MAX_TEST_APS = 6
with warnings.catch_warnings():
    warnings.simplefilter("ignore", DeprecationWarning)
    FAMILIES = families(random_count=RANDOM_COUNT, random_seed=1)
CASES = [
    (family, text)
    for family, texts in FAMILIES.items()
    for text in texts
    if len(spot.atomic_prop_collect(spot.formula(text))) <= MAX_TEST_APS
]


def _spot_of(automaton: Any) -> Any:
    return spot.automaton(to_hoa(automaton))


def _ours(text: str) -> Any:
    return translate(parse_ltl(to_tlmpc(spot.formula(text))))


@pytest.mark.parametrize(
    ("family", "text"), CASES, ids=[f"{f}-{i}" for i, (f, _t) in enumerate(CASES)]
)
def test_equivalent_to_spot(family: str, text: str) -> None:
    ours = _ours(text)
    theirs = spot.translate(spot.formula(text), "TGBA", "Small", "High")
    assert spot.are_equivalent(_spot_of(ours), theirs), (family, text)
    if ours.num_acc <= 4:  # the degeneralized Büchi automaton too
        assert spot.are_equivalent(_spot_of(degeneralize(ours)), theirs), (family, text)


@pytest.mark.slow
@pytest.mark.parametrize("family", ["robotics", "eh", "sb", "dac"])
def test_no_more_states_than_spot(family: str) -> None:
    """On these families tlmpc matches Spot formula by formula (a regression guard)."""
    larger = []
    for text in (t for f, t in CASES if f == family):
        ours = _ours(text).num_states
        theirs = spot.translate(spot.formula(text), "TGBA", "Small", "High").num_states()
        if ours > theirs:
            larger.append((text, ours, theirs))
    assert larger == []


def test_dwyer_patterns_within_a_few_states_of_spot() -> None:
    ours = theirs = 0
    for text in (t for f, t in CASES if f == "dac"):
        ours += _ours(text).num_states
        theirs += spot.translate(spot.formula(text), "TGBA", "Small", "High").num_states()
    assert ours <= theirs * 1.05, (ours, theirs)


def _letters_constraint(letters: list[frozenset[str]], aps: list[str]) -> Any:
    """G(one of the letters): exactly the words over ``letters``."""
    cubes = []
    for letter in letters:
        literals = [p if p in letter else f"!{p}" for p in aps] or ["1"]
        cubes.append("(" + " & ".join(literals) + ")")
    return spot.formula("G(" + (" | ".join(cubes) or "0") + ")")


@pytest.mark.slow
@given(
    formulas(("a", "b", "c")),
    st.lists(st.frozensets(st.sampled_from(["a", "b", "c"])), min_size=1, max_size=5),
)
def test_restricted_to_letters_agrees_with_spot_on_those_letters(
    formula: Formula, letters: list[frozenset[str]]
) -> None:
    ours = translate(formula, letters=[sorted(x) for x in letters])
    text = to_text(formula)
    constraint = _letters_constraint(letters, ["a", "b", "c"])
    mine = spot.product(_spot_of(ours), spot.translate(constraint))
    theirs = spot.translate(spot.formula_And([spot.formula(text), constraint]))
    assert spot.are_equivalent(mine, theirs), (text, letters)
    # The artifacts say the automaton is restricted, and keep the letters.
    hoa = to_hoa(ours)
    assert "restricted to" in hoa.splitlines()[2]
    assert parse_hoa(hoa).letters == ours.letters
    document = json.loads(json.dumps(automaton_to_json(ours)))
    assert automaton_from_json(document).letters == ours.letters


@given(formulas(("a", "b", "c", "d"), max_leaves=10))
def test_random_formulas_over_every_operator_agree_with_spot(formula: Formula) -> None:
    ours = translate(formula)
    theirs = spot.translate(spot.formula(to_text(formula)))
    assert spot.are_equivalent(_spot_of(ours), theirs), to_text(formula)


def test_unrestricted_hoa_names_the_formula() -> None:
    hoa = to_hoa(translate(parse_ltl("G F a")))
    assert 'name: "G F a"' in hoa
    assert "tlmpc-letters" not in hoa
    assert parse_hoa(hoa).letters is None
