"""Transition-based generalized Büchi automata (stage 4 output).

Acceptance: a run is accepting iff every acceptance set ``0 .. num_acc-1`` is visited by
infinitely many of its edges (``num_acc == 0``: every infinite run is accepting).  A
state-based Büchi automaton (after degeneralization) is the special case ``num_acc == 1``
with ``state_based=True``, where all out-edges of an accepting state carry mark 0.

Run convention (the product relies on it): the automaton reads the label of every state of
the transition system, including the first; the run starts in ``initial`` and takes an edge
for the start triangle's label.
"""

from __future__ import annotations

from dataclasses import dataclass

from tlmpc.ltl.ast import Formula


@dataclass(frozen=True, slots=True, kw_only=True)
class Edge:
    """``src --guard / {marks}--> dst``; ``guard`` is a propositional formula over ``aps``."""

    src: int
    dst: int
    guard: Formula
    marks: frozenset[int] = frozenset()


@dataclass(frozen=True, slots=True, kw_only=True)
class Automaton:
    """A TGBA (or a state-based BA when ``state_based``) over atomic propositions ``aps``."""

    aps: tuple[str, ...]
    num_states: int
    initial: int
    edges: tuple[Edge, ...]
    num_acc: int
    state_names: tuple[str, ...] = ()
    formula: str = ""
    state_based: bool = False
    #: The label sets the automaton was built for (each the names true at once), when the
    #: translation was restricted to a map's letters: its language is then the formula's
    #: only on words over these letters.  None: every valuation of ``aps`` is a letter.
    letters: tuple[tuple[str, ...], ...] | None = None
