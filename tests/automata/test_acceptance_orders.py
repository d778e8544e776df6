"""Awaiting a generalized automaton's acceptance sets in another order
(``tlmpc.automata.degeneralize.acceptance_orders`` and ``reorder_acceptance``).

Oracles: a brute force over permutations (the orders are one per cycle up to rotation and
reversal) and Spot (the reordered automaton and its degeneralization accept the formula's
language).
"""

from __future__ import annotations

import itertools

import pytest

from tlmpc.automata import degeneralize, to_hoa, translate
from tlmpc.automata.degeneralize import acceptance_orders, reorder_acceptance
from tlmpc.ltl.parser import parse_ltl


def _canonical(cycle: tuple[int, ...]) -> tuple[int, ...]:
    """The least rotation of the cycle or of its reverse."""
    forms = []
    for seq in (cycle, tuple(reversed(cycle))):
        forms += [seq[i:] + seq[:i] for i in range(len(seq))]
    return min(forms)


@pytest.mark.parametrize("count", range(1, 7))
def test_orders_are_one_per_cycle_up_to_rotation_and_direction(count: int) -> None:
    orders = list(acceptance_orders(count))
    assert orders[0] == tuple(range(count))
    classes = {_canonical(p) for p in itertools.permutations(range(count))}
    assert len(orders) == len(classes)
    assert {_canonical(o) for o in orders} == classes


@pytest.mark.parametrize(
    "text", ["G F a & G F b & G F c & G F d", "G F a & G F (b | c) & G !d & G F c"]
)
def test_a_reordered_automaton_and_its_degeneralization_keep_the_language(text: str) -> None:
    spot = pytest.importorskip("spot")
    automaton = translate(parse_ltl(text))
    reference = spot.formula(text)
    for order in acceptance_orders(automaton.num_acc):
        reordered = reorder_acceptance(automaton, order)
        for candidate in (reordered, degeneralize(reordered)):
            parsed = spot.automaton(to_hoa(candidate))
            assert spot.are_equivalent(parsed, reference), (order, candidate.num_acc)


def test_a_reordering_that_is_no_order_is_refused() -> None:
    automaton = translate(parse_ltl("G F a & G F b & G F c"))
    with pytest.raises(ValueError, match="not an order"):
        reorder_acceptance(automaton, (0, 1, 1))
