"""The simulation reductions charge their budget for every pair of states they weigh, so the
budget bites on automata with many states and few edges, where the work is in the pairs."""

from __future__ import annotations

import pytest

from tlmpc.automata import work
from tlmpc.automata.model import Automaton, Edge
from tlmpc.automata.simulation import Alphabet, simulation
from tlmpc.ltl.ast import Const


def _self_loops(n: int) -> Automaton:
    """``n`` states, each with one self-loop on every letter: every state simulates every
    other, found in a single sweep."""
    edges = tuple(Edge(src=q, dst=q, guard=Const(True)) for q in range(n))
    return Automaton(aps=("a",), num_states=n, initial=0, edges=edges, num_acc=0)


def test_every_pair_weighed_is_charged() -> None:
    n = 60
    automaton = _self_loops(n)
    before = work.spent()
    relation = simulation(automaton, Alphabet(automaton.aps, None), float("inf"))
    charged = work.spent() - before
    assert all(all(row) for row in relation)
    # The pairs are weighed three times: the first guess of the relation (n^2 pairs), the
    # sweep walking each target's n simulators for each of the n states, the result (n^2).
    assert charged >= 3 * n * n


def test_the_budget_stops_the_pairs() -> None:
    n = 60
    automaton = _self_loops(n)
    # the edges, the letters and the sweep's own steps are a few units per state: a budget of
    # two and a half weighings of the pairs is short of the three the relation needs
    with pytest.raises(work.OutOfBudget):
        simulation(automaton, Alphabet(automaton.aps, None), work.spent() + 5 * n * n // 2)
