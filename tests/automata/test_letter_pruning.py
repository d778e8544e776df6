"""A translation restricted to a map's letters never builds terms no letter allows."""

from __future__ import annotations

from tlmpc.automata import translate
from tlmpc.automata.terms import expand, from_ast, restrict_letters
from tlmpc.ltl import parse_ltl


def _patrol(n: int) -> str:
    return " & ".join(f"G F r{i}" for i in range(n))


def test_patrol_over_many_disjoint_regions_expands_linearly() -> None:
    # 12 regions: 2^12 terms without the restriction (a mutant stays quick to catch)
    names = [f"r{i}" for i in range(12)]
    letters = [frozenset(), *(frozenset([name]) for name in names)]
    root = from_ast(parse_ltl(f"G({' & '.join(f'F {name}' for name in names)})"))
    previous = restrict_letters(letters)
    try:
        terms = expand(root)
    finally:
        restrict_letters(previous)
    # about one term per letter (a region now, or none)
    assert len(terms) <= 2 * len(letters)
    for pos, neg, _, _ in terms:
        assert any(pos <= letter and not neg & letter for letter in letters)


def test_the_restriction_is_undone_after_a_translation() -> None:
    translate(parse_ltl("F a & F b"), letters=[(), ("a",), ("b",)])
    assert restrict_letters(None) is None  # nothing left behind for the next translation


def test_patrol_over_disjoint_regions_is_one_state() -> None:
    letters = [(), *((f"r{i}",) for i in range(12))]
    automaton = translate(parse_ltl(_patrol(12)), letters=letters)
    assert automaton.num_states == 1
    assert len(automaton.edges) == len(letters)
    assert automaton.num_acc == 12
