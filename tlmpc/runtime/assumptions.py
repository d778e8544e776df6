"""The environment's assumptions, tracked along a run, letter by letter.

The same GR(1) reading the game is built from (:mod:`tlmpc.reactive.fragment`): each
assumption is a condition on the first letter, a condition on every letter (``G ψ``), a
recurrence (``G F χ``), or a deterministic monitor automaton (its state follows the letters; a
letter it cannot read breaks the assumption; its acceptance sets are recurrences).  A letter
is the set of true propositions: the regions of the robot's face and the sensors that are on.

Environments ask :meth:`AssumptionTracker.allows` before they change a sensor, and how long
each recurrence has waited (:meth:`AssumptionTracker.waiting`), so that they keep the safety
assumptions always and meet every fairness assumption within a bound.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass

from tlmpc.automata.guards import holds
from tlmpc.base.errors import InvalidInputError
from tlmpc.mission.model import Mission, TaskPart
from tlmpc.reactive.fragment import Piece, reading

Letter = frozenset[str]


@dataclass(frozen=True, slots=True)
class Recurrence:
    """One fairness obligation: a ``G F`` piece, or one acceptance set of a monitor."""

    part: TaskPart
    piece: int
    mark: int | None  # the acceptance set of a monitor piece; None for G F χ


class AssumptionTracker:
    """Where every assumption stands after the letters read so far."""

    def __init__(self, mission: Mission) -> None:
        assert mission.reactive is not None
        parts = [(part, "env") for part in mission.reactive.assumptions]
        pieces, problems = reading(parts, mission.source)  # type: ignore[arg-type]
        if problems:  # compile refused these already: a hand-edited mission.json
            raise InvalidInputError(problems)
        self.pieces: tuple[Piece, ...] = tuple(pieces)
        self.recurrences: tuple[Recurrence, ...] = tuple(
            item
            for index, piece in enumerate(pieces)
            for item in (
                [Recurrence(piece.part, index, None)]
                if piece.kind == "recurrence"
                else [
                    Recurrence(piece.part, index, mark)
                    for mark in range(piece.automaton.num_acc if piece.automaton else 0)
                ]
            )
        )
        self._states: list[int | None] = [None] * len(pieces)
        self._waiting = [0] * len(self.recurrences)
        self._started = False

    @property
    def started(self) -> bool:
        """Whether the first letter was read."""
        return self._started

    def broken_by(self, letter: Collection[str]) -> TaskPart | None:
        """The first assumption the next letter would break (None: it keeps them all)."""
        for index, piece in enumerate(self.pieces):
            if self._after(index, piece, letter) is _BROKEN:
                return piece.part
        return None

    def allows(self, letter: Collection[str]) -> bool:
        """Whether the next letter keeps every safety assumption."""
        return self.broken_by(letter) is None

    def fulfils(self, letter: Collection[str]) -> list[bool]:
        """For each recurrence, whether reading ``letter`` next would meet it."""
        met = []
        for item in self.recurrences:
            piece = self.pieces[item.piece]
            if item.mark is None:
                met.append(holds(piece.formula, letter))
            else:
                edge = self._edge(item.piece, piece, letter)
                met.append(edge is not None and item.mark in edge[1])
        return met

    def waiting(self) -> list[int]:
        """For each recurrence, the letters read since it was last met."""
        return list(self._waiting)

    def read(self, letter: Collection[str]) -> None:
        """Take ``letter`` as the next letter (it must keep the assumptions)."""
        met = self.fulfils(letter)
        for index, piece in enumerate(self.pieces):
            after = self._after(index, piece, letter)
            assert after is not _BROKEN, "read a letter that breaks an assumption"
            if piece.kind == "monitor":
                assert isinstance(after, int)
                self._states[index] = after
        self._waiting = [0 if hit else w + 1 for hit, w in zip(met, self._waiting, strict=True)]
        self._started = True

    # --- internals ---------------------------------------------------------------------

    def _edge(
        self, index: int, piece: Piece, letter: Collection[str]
    ) -> tuple[int, tuple[int, ...]] | None:
        automaton = piece.automaton
        assert automaton is not None
        state = self._states[index] if self._started else None
        for edge in automaton.edges:
            source_ok = edge.src == state if state is not None else edge.src == automaton.initial
            if source_ok and holds(edge.guard, letter):
                return edge.dst, tuple(edge.marks)
        return None

    def _after(self, index: int, piece: Piece, letter: Collection[str]) -> int | object | None:
        if piece.kind == "init":
            return None if self._started or holds(piece.formula, letter) else _BROKEN
        if piece.kind == "invariant":
            return None if holds(piece.formula, letter) else _BROKEN
        if piece.kind == "recurrence":
            return None
        edge = self._edge(index, piece, letter)
        return _BROKEN if edge is None else edge[0]


_BROKEN = object()


def letter_of(regions: Sequence[str], true_names: Collection[str]) -> Letter:
    """The letter of a face's regions and the propositions that are on."""
    return frozenset((*regions, *true_names))


__all__ = ["AssumptionTracker", "Letter", "Recurrence", "letter_of"]
