"""The GR(1) reading of a reactive mission's task and assumptions.

Every part the user wrote (a task phrase, a top-level conjunct of ``ltl``, an assumption) is
split into *pieces* of the forms a GR(1) game states directly:

* ``init``: a condition on the first instant (no temporal operator);
* ``invariant``: ``G ψ`` — ψ holds at every instant;
* ``recurrence``: ``G F χ`` — χ holds again and again;
* ``monitor``: any other formula whose automaton is deterministic (or, for a safety formula,
  becomes deterministic by the subset construction): ``G(p -> F q)``, ``G(p -> (q W r))``,
  ``F(a & F b)``, ``!a U b`` ... The game carries the automaton's state as a variable of the
  player the part belongs to; its acceptance sets become recurrence goals on transitions.

What has no such reading — persistence ``F G p``, or any formula whose automaton needs to
guess — is reported (Q102) with the rewrites that stay in the fragment.  The reading is exact:
a word satisfies the part iff the piece's constraints hold along it (docs/semantics.md).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Literal

from tlmpc.automata.guards import holds
from tlmpc.automata.model import Automaton, Edge
from tlmpc.base.errors import Diagnostic, error
from tlmpc.ltl.ast import (
    And,
    Const,
    Eventually,
    Formula,
    Globally,
    Not,
    Prop,
    bounded_operators,
    conjoin,
    disjoin,
    is_propositional,
)
from tlmpc.ltl.printer import to_text
from tlmpc.mission.model import TaskPart

PieceKind = Literal["init", "invariant", "recurrence", "monitor"]
Owner = Literal["env", "sys"]

#: A monitor's automaton is determinised over at most this many propositions (2^k letters).
MAX_MONITOR_PROPS = 12
#: ... and into at most this many states.
MAX_MONITOR_STATES = 512


@dataclass(frozen=True, slots=True)
class Piece:
    """One GR(1) constraint of a player, with the part of the mission it came from.

    ``formula`` is the condition (``init``, ``invariant``, ``recurrence``) or the whole
    temporal formula (``monitor``, whose deterministic ``automaton`` the game tracks).
    """

    owner: Owner
    kind: PieceKind
    formula: Formula
    part: TaskPart
    automaton: Automaton | None = None

    def describe(self) -> str:
        """The piece in words, as ``tlmpc check --explain`` prints it."""
        who = "the environment" if self.owner == "env" else "the robot"
        text = to_text(self.formula)
        if self.kind == "init":
            return f"{text}: initially ({who})"
        if self.kind == "invariant":
            return f"G {_wrapped(text)}: at every instant ({who})"
        if self.kind == "recurrence":
            return f"G F {_wrapped(text)}: again and again ({who}'s goal)"
        assert self.automaton is not None
        goals = self.automaton.num_acc
        return (
            f"{text}: tracked by a deterministic automaton of {self.automaton.num_states} "
            f"state(s) ({who}'s {'memory and ' + str(goals) + ' goal(s)' if goals else 'memory'})"
        )


def _wrapped(text: str) -> str:
    return text if text.isidentifier() else f"({text})"


def pieces(part: TaskPart, owner: Owner, file: str | None = None) -> list[Piece]:
    """The GR(1) pieces of one part; raises :class:`NotGr1` when a conjunct has none."""
    timed = bounded_operators(part.formula)
    if timed:  # (the game has no clocks: no automaton reads a time bound)
        raise NotGr1(
            error(
                "L045",
                f"a reactive mission cannot take the time bound of `{to_text(timed[0])}`: "
                "its task is synthesised as a game, which has no clocks",
                hint="state this part without the bound (visit, not visit within); `tlmpc "
                "verify LOG --mission MISSION` checks a bound on a run's log",
                file=file,
                line=part.line,
                col=part.col,
            )
        )
    found: list[Piece] = []
    for conjunct in _conjuncts(part.formula):
        found.append(_piece(conjunct, part, owner, file))
    return found


class NotGr1(Exception):
    """A part of the mission has no GR(1) reading; ``diagnostic`` says why and what to write."""

    def __init__(self, diagnostic: Diagnostic) -> None:
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic


def _conjuncts(formula: Formula) -> list[Formula]:
    """Top-level conjuncts, with ``G`` distributed over ``&`` (``G(a & b) = G a & G b``)."""
    if isinstance(formula, And):
        return [c for arg in formula.args for c in _conjuncts(arg)]
    if isinstance(formula, Globally) and isinstance(formula.arg, And):
        return [c for arg in formula.arg.args for c in _conjuncts(Globally(arg))]
    if isinstance(formula, Const) and formula.value:
        return []
    return [formula]


def _piece(formula: Formula, part: TaskPart, owner: Owner, file: str | None) -> Piece:
    if is_propositional(formula):
        return Piece(owner, "init", formula, part)
    if isinstance(formula, Globally) and is_propositional(formula.arg):
        return Piece(owner, "invariant", formula.arg, part)
    if (
        isinstance(formula, Globally)
        and isinstance(formula.arg, Eventually)
        and is_propositional(formula.arg.arg)
    ):
        return Piece(owner, "recurrence", formula.arg.arg, part)
    return Piece(owner, "monitor", formula, part, _monitor(formula, part, file))


def _monitor(formula: Formula, part: TaskPart, file: str | None) -> Automaton:
    from tlmpc.automata import translate

    automaton = translate(formula)
    if _deterministic(automaton):
        return automaton
    if automaton.num_acc == 0:
        determinised = _subset_construction(automaton)
        if determinised is not None:
            return determinised
    raise NotGr1(_not_gr1(formula, part, file))


def _letters(aps: tuple[str, ...]) -> list[frozenset[str]]:
    return [
        frozenset(ap for ap, bit in zip(aps, bits, strict=True) if bit)
        for bits in itertools.product((False, True), repeat=len(aps))
    ]


def _deterministic(automaton: Automaton) -> bool:
    """Whether no letter enables two edges out of one state."""
    if len(automaton.aps) > MAX_MONITOR_PROPS:
        return False
    outgoing: dict[int, list[Edge]] = {}
    for edge in automaton.edges:
        outgoing.setdefault(edge.src, []).append(edge)
    for letter in _letters(automaton.aps):
        for edges in outgoing.values():
            if sum(holds(edge.guard, letter) for edge in edges) > 1:
                return False
    return True


def _subset_construction(automaton: Automaton) -> Automaton | None:
    """A deterministic automaton of a safety automaton (every run accepting): states are the
    sets of states a run can be in; a letter no state can read has no edge."""
    if len(automaton.aps) > MAX_MONITOR_PROPS:
        return None
    letters = _letters(automaton.aps)
    start = frozenset({automaton.initial})
    index: dict[frozenset[int], int] = {start: 0}
    todo = [start]
    edges: list[Edge] = []
    while todo:
        current = todo.pop()
        successors: dict[frozenset[int], list[frozenset[str]]] = {}
        for letter in letters:
            after = frozenset(
                e.dst for e in automaton.edges if e.src in current and holds(e.guard, letter)
            )
            if after:
                successors.setdefault(after, []).append(letter)
        for after, readers in successors.items():
            if after not in index:
                if len(index) >= MAX_MONITOR_STATES:
                    return None
                index[after] = len(index)
                todo.append(after)
            guard = disjoin(
                [
                    conjoin([Prop(ap) if ap in letter else _negated(ap) for ap in automaton.aps])
                    for letter in readers
                ]
            )
            edges.append(Edge(src=index[current], dst=index[after], guard=guard))
    return Automaton(
        aps=automaton.aps,
        num_states=len(index),
        initial=0,
        edges=tuple(edges),
        num_acc=0,
        formula=automaton.formula,
    )


def _negated(ap: str) -> Formula:
    return Not(Prop(ap))


def _not_gr1(formula: Formula, part: TaskPart, file: str | None) -> Diagnostic:
    text = to_text(formula)
    persistence = isinstance(formula, Eventually) and isinstance(formula.arg, Globally)
    why = (
        "'eventually always' (F G) asks the robot to settle without saying when"
        if persistence
        else "tlmpc finds no deterministic automaton for it, and a game tracks only those"
    )
    return error(
        "Q102",
        f"{text!r} is outside the GR(1) fragment tlmpc synthesises: {why}",
        hint="write it with the forms a game states directly: a condition at the start, "
        "G of a condition, G F of a condition, G(p -> F q), G(p -> (q W r)), or a reach "
        "sequence F(a & F b); e.g. F G p becomes G F p (again and again) or "
        "G(p -> G p) & F p (reach, then stay)",
        file=file,
        line=part.line,
        col=part.col,
    )


def reading(
    parts: list[tuple[TaskPart, Owner]], file: str | None
) -> tuple[list[Piece], list[Diagnostic]]:
    """Every part's pieces, and a diagnostic for each part that has no GR(1) reading."""
    found: list[Piece] = []
    problems: list[Diagnostic] = []
    for part, owner in parts:
        try:
            found.extend(pieces(part, owner, file))
        except NotGr1 as exc:
            problems.append(exc.diagnostic)
    return found, problems


__all__ = ["NotGr1", "Piece", "PieceKind", "pieces", "reading"]
