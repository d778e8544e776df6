"""Chains of `<->` are refused (P041) before their negation normal form is built.

`a <-> b` is written `(a & b) | (!a & !b)` in NNF, both sides twice, so a chain of n
equivalences has about 2^n operators: `F (p25 <-> (p24 <-> ... (p1 <-> p0)))`, 280
characters, ran for minutes and gigabytes where Spot answers in milliseconds.
"""

from __future__ import annotations

import random

import pytest

from tlmpc.automata import translate
from tlmpc.base.errors import UsageError
from tlmpc.ltl import parse_ltl
from tlmpc.ltl.ast import Formula
from tlmpc.ltl.transform import MAX_NORMAL_FORM_SIZE, nnf, normal_form_size


def _chain(n: int, operator: str = "F") -> str:
    text = "p0"
    for i in range(1, n):
        text = f"(p{i} <-> {text})"
    return f"{operator} {text}"


def _written(formula: Formula) -> int:
    return sum(1 for _ in formula.walk())


@pytest.mark.parametrize("n", [17, 26, 60])
def test_a_long_chain_of_equivalences_is_refused(n: int) -> None:
    formula = parse_ltl(_chain(n))
    for run in (nnf, translate):
        with pytest.raises(UsageError) as refused:
            run(formula)
        assert [d.code for d in refused.value.diagnostics] == ["P041"]
        assert "<->" in refused.value.diagnostics[0].message


def test_a_chain_under_the_budget_still_translates() -> None:
    formula = parse_ltl(_chain(10, "G"))
    assert _written(nnf(formula)) <= MAX_NORMAL_FORM_SIZE
    automaton = translate(formula)
    assert automaton.num_states == 1
    assert automaton.num_acc == 0


def _random_formula(rng: random.Random, depth: int, operators: list[str]) -> str:
    if depth == 0 or rng.random() < 0.2:
        return rng.choice(["a", "b", "c", "true", "false"])
    operator = rng.choice(operators)
    if operator in ("!", "F", "G", "F[0,2]", "G[1,2]"):
        return f"{operator} ({_random_formula(rng, depth - 1, operators)})"
    left = _random_formula(rng, depth - 1, operators)
    return f"({left}) {operator} ({_random_formula(rng, depth - 1, operators)})"


UNARY_AND_TEMPORAL = ["!", "F", "G", "F[0,2]", "G[1,2]", "U", "R", "W", "M", "U[1,3]"]
BOOLEAN = ["&", "|", "->", "<->"]


@pytest.mark.parametrize(
    ("operators", "exact"), [(UNARY_AND_TEMPORAL, True), (UNARY_AND_TEMPORAL + BOOLEAN, False)]
)
def test_the_size_is_that_of_the_written_normal_form(operators: list[str], exact: bool) -> None:
    """Counted without building it: exact when there is no `&`/`|` to flatten, else a bound."""
    rng = random.Random(7)
    for _ in range(400):
        formula = parse_ltl(_random_formula(rng, rng.randint(1, 6), operators))
        for negate in (False, True):
            size, written = normal_form_size(formula, negate), _written(nnf(formula, negate))
            assert size == written if exact else size >= written, (formula, negate)
