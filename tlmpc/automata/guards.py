"""Evaluating propositional guards on letters, and the planner's successor table."""

from __future__ import annotations

from collections.abc import Collection, Sequence

from tlmpc.automata.model import Automaton
from tlmpc.ltl.ast import (
    And,
    Const,
    Equiv,
    Formula,
    Implies,
    Not,
    Or,
    Prop,
)


def holds(guard: Formula, letter: Collection[str]) -> bool:
    """Truth of the propositional ``guard`` when exactly the props in ``letter`` are true."""
    if isinstance(guard, Const):
        return guard.value
    if isinstance(guard, Prop):
        return guard.name in letter
    if isinstance(guard, Not):
        return not holds(guard.arg, letter)
    if isinstance(guard, And):
        return all(holds(a, letter) for a in guard.args)
    if isinstance(guard, Or):
        return any(holds(a, letter) for a in guard.args)
    if isinstance(guard, Implies):
        return not holds(guard.left, letter) or holds(guard.right, letter)
    if isinstance(guard, Equiv):
        return holds(guard.left, letter) == holds(guard.right, letter)
    raise ValueError(f"guards are propositional, got {guard!r}")


def guard_holds(guard: Formula, letter: Collection[str]) -> bool:
    """Public name of :func:`holds`."""
    return holds(guard, letter)


def successor_table(
    automaton: Automaton, letters: Sequence[Sequence[str]]
) -> list[list[tuple[tuple[int, int], ...]]]:
    """``table[letter][state]``: the (target, mark bitmask) pairs that ``letter`` enables.

    Letters are projected on the automaton's propositions first, so a map with a thousand
    regions but a task over three costs a handful of guard evaluations per edge.
    """
    aps = set(automaton.aps)
    projections: dict[frozenset[str], list[list[tuple[int, int]]]] = {}
    table: list[list[tuple[tuple[int, int], ...]]] = []
    cache: dict[frozenset[str], list[tuple[tuple[int, int], ...]]] = {}
    empty: frozenset[str] = frozenset()
    for letter in letters:
        # Most letters of a large map name no proposition of the task: one set operation.
        common = aps.intersection(letter)
        key = frozenset(common) if common else empty
        row = cache.get(key)
        if row is None:
            per_state: list[list[tuple[int, int]]] = [[] for _ in range(automaton.num_states)]
            for edge in automaton.edges:
                if holds(edge.guard, key):
                    mask = 0
                    for mark in edge.marks:
                        mask |= 1 << mark
                    per_state[edge.src].append((edge.dst, mask))
            row = [tuple(dict.fromkeys(successors)) for successors in per_state]
            cache[key] = row
            projections[key] = per_state
        table.append(row)
    return table
