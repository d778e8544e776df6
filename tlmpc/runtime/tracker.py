"""What the robot has seen, as automaton states: the task's progress along the real run.

The automaton is nondeterministic, so the run is tracked as the *set* of states some run of
the automaton can be in after reading the labels of the triangles actually visited.  A state
of the set from which an accepting continuation exists is as good as any other: a finite
history never decides Büchi acceptance, so any plan accepted from one of these states makes
the whole run accepted.  An empty set means the history already violates the task.

The robot spends a positive time in every triangle it enters, so the label of a triangle is
read once or more (stuttering): the set after entering is closed under re-reading its letter,
which is also what the planner's stutter steps do.  Under the closed convention the automaton
(built over the rewritten task, see :mod:`tlmpc.planning.boundary`) also reads, exactly once,
the letter of each point instant: the start point, every edge crossing and every corner a
vertex passage goes through (:meth:`TaskTracker.read_point`).
"""

from __future__ import annotations

from collections.abc import Sequence

from tlmpc.automata.guards import successor_table
from tlmpc.automata.model import Automaton


def working_automaton(automaton: Automaton) -> Automaton:
    """The automaton the planner searched (degeneralized when it has several sets): the
    witness's automaton states are numbered in it."""
    from tlmpc.automata.degeneralize import degeneralize

    return degeneralize(automaton) if automaton.num_acc >= 2 else automaton


class TaskTracker:
    """Successor sets of an automaton over a map's letters (label sets)."""

    def __init__(self, automaton: Automaton, letters: Sequence[Sequence[str]]) -> None:
        self.automaton = automaton
        table = successor_table(automaton, letters)
        self._next: list[list[frozenset[int]]] = [
            [frozenset(dst for dst, _ in row) for row in per_letter] for per_letter in table
        ]
        self._point_next: dict[tuple[str, ...], list[frozenset[int]]] = {}

    def initial(self, letter: int) -> frozenset[int]:
        """The states after reading the start triangle's ``letter``."""
        return self.read(frozenset({self.automaton.initial}), letter)

    def read_point(self, states: frozenset[int], letter: Sequence[str]) -> frozenset[int]:
        """The states after one point instant labelled ``letter`` (a label set, read once:
        a point has no duration to stutter over)."""
        key = tuple(sorted(letter))
        row = self._point_next.get(key)
        if row is None:
            (per_letter,) = successor_table(self.automaton, [key])
            row = [frozenset(dst for dst, _ in edges) for edges in per_letter]
            self._point_next[key] = row
        found: set[int] = set()
        for state in states:
            found |= row[state]
        return frozenset(found)

    def read(self, states: frozenset[int], letter: int) -> frozenset[int]:
        """The states after entering a triangle labelled ``letter`` (read once or more)."""
        row = self._next[letter]
        current: set[int] = set()
        for state in states:
            current |= row[state]
        frontier = set(current)
        while frontier:  # stuttering: the same letter again, as often as it leads anywhere
            found = set().union(*(row[state] for state in frontier)) - current
            current |= found
            frontier = found
        return frozenset(current)
