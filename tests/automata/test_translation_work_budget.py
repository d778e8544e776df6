"""The translation's work is bounded by counts of operations, never by a clock.

Many independent goals over a map's exclusive letters (``F p0 & ... & F p12``, one region at a
time) make an automaton of 2^n states whose edges stay under the edges' budget: expanding them
is refused (P041) once it passes :data:`MAX_EXPLORATION_UNITS`, and the simulation reductions
count the work of their relation (a square of the states) and of its bit loops, so their
budget bites on automata of thousands of states.  The oracle for the sizes: a conjunction of n
independent eventualities over exclusive letters has exactly 2^n reachable subsets of goals
still to meet, which the raw automaton has as states.
"""

from __future__ import annotations

import pytest

from tlmpc.automata import translate, work
from tlmpc.automata.simulation import Alphabet, simulation
from tlmpc.automata.translate import MAX_EXPLORATION_UNITS
from tlmpc.base.errors import UsageError
from tlmpc.ltl import parse_ltl


def _cover(n: int) -> tuple[str, list[list[str]]]:
    """``F p0 & ... & F p(n-1)`` and the exclusive letters of n disjoint regions."""
    text = " & ".join(f"F p{i}" for i in range(n))
    return text, [[]] + [[f"p{i}"] for i in range(n)]


@pytest.mark.parametrize("n", [4, 7])
def test_a_few_goals_translate_with_every_subset_as_a_state(n: int) -> None:
    text, letters = _cover(n)
    raw = translate(parse_ltl(text), letters=letters, simplify=False)
    assert raw.num_states == 2**n


def test_many_goals_over_exclusive_letters_are_refused_within_the_work_budget() -> None:
    text, letters = _cover(13)
    before = work.spent()
    with pytest.raises(UsageError) as caught:
        translate(parse_ltl(text), letters=letters, simplify=False)
    (problem,) = caught.value.diagnostics
    assert problem.code == "P041"
    assert "units of work" in problem.message
    # refused as the count passed the budget: the translation's own count, not a clock
    assert work.spent() - before <= 2 * MAX_EXPLORATION_UNITS


def test_the_simulation_relation_charges_the_square_of_the_states() -> None:
    text, letters = _cover(7)
    raw = translate(parse_ltl(text), letters=letters, simplify=False)
    n = raw.num_states
    alphabet = Alphabet(raw.aps, [frozenset(x) for x in letters])
    before = work.spent()
    simulation(raw, alphabet, float("inf"))
    assert work.spent() - before >= 2 * n * n
    with pytest.raises(work.OutOfBudget):
        simulation(raw, alphabet, work.spent() + n * n - 1)
