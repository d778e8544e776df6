"""Live monitoring: each conjunct's three-valued verdict as the poses of a running robot arrive.

The semantics is the offline verifier's on the log so far (an open log: ``satisfied``,
``violated`` or ``inconclusive``), in bounded memory:

* poses go through the same :class:`~tlmpc.fleet.stream.Reducer` as a streamed log, so only
  the samples that shape the verdict are looked at further;
* between kept samples the path stays in one cell of the map, so nothing changes; when
  samples are kept, the new stretch is cut into pieces by the verifier's own
  :func:`~tlmpc.verify.pieces.build_pieces` and every conjunct's residue is progressed through
  them (:mod:`tlmpc.fleet.progression`), then evaluated on the last pieces and the unknown
  future, exactly as the offline verifier evaluates the whole log;
* the workspace (free space, holes, the body's radius) is checked on each new stretch by
  :func:`tlmpc.verify.verify_trace` itself.

Memory is the residues (combinations of the task's subformulas) and the reducer's anchor:
constant in the length of the log.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import shapely

from tlmpc.base.errors import UsageError, error
from tlmpc.fleet.progression import Piece, Residue, progress, residue, value
from tlmpc.fleet.stream import Reducer
from tlmpc.ltl.ast import And, Formula, bounded_operators
from tlmpc.ltl.printer import to_text
from tlmpc.verify import TraceInput, from_document, verify_trace
from tlmpc.verify.pieces import boundary_membership, build_pieces, region_membership
from tlmpc.verify.samples import sample_diagnostics

FloatArray = npt.NDArray[np.float64]

OUTCOMES = {1: "satisfied", 0: "inconclusive", -1: "violated"}


@dataclass(frozen=True, slots=True)
class Change:
    """A verdict that changed: of a conjunct, of the whole ``task``, or of the ``workspace``,
    at ``time`` (the pose's own stamp).

    A conjunct's or the task's ``satisfied`` or ``violated`` is final: no pose after it
    changes it (the open log's verdict, LTL3).  The workspace is only ever ``violated``."""

    time: float
    subject: str
    verdict: str
    message: str | None = None


class Monitor:
    """Feed poses with :meth:`add`; :meth:`changes` tells what changed since the last call."""

    def __init__(self, document: Mapping[str, Any], *, convention: str | None = None) -> None:
        self.trace: TraceInput = from_document(
            {**document, "points": [[0.0, 0.0, 0.0]]}, file=None, convention=convention
        )
        self.convention = self.trace.convention
        formula = self.trace.formula
        bounded = bounded_operators(formula)
        if bounded:
            raise UsageError(
                error(
                    "F010",
                    f"the live monitor does not decide time bounds yet ({bounded[0]})",
                    hint="verify the log when it ends: tlmpc verify LOG --mission MISSION "
                    "decides time bounds exactly",
                )
            )
        self.conjuncts: list[Formula] = (
            list(formula.args) if isinstance(formula, And) else [formula]
        )
        mentioned = formula.props()
        self.names = [n for n in self.trace.regions if n in mentioned]
        self.regions = {n: self.trace.regions[n] for n in self.names}
        self.shapes = [shapely.Polygon(self.regions[n]) for n in self.names]
        self.residues: list[Residue] = [residue(c) for c in self.conjuncts]
        self.task: Residue = residue(formula)
        self.reducer = Reducer(document)
        self.workspace = self.trace.boundary_polygon is not None
        self.last: FloatArray | None = None  # the last kept sample, pieces progressed to it
        self.previous_time: float | None = None
        self.last_pose: tuple[float, float, float, int | None] | None = None
        self.origin: float | None = None
        self.verdicts: dict[str, str] = {}
        self.excursion: Change | None = None
        self.pending: list[Change] = []
        self.samples = 0

    # -- input --------------------------------------------------------------------------------

    def add(
        self,
        t: float,
        x: float,
        y: float,
        *,
        line: int | None = None,
        column: Callable[[int], Mapping[str, Any]] | None = None,
    ) -> None:
        """The next pose; the verifier's own sample checks (V003, V005, V020, V024; exit 2)
        refuse a pose it would refuse, at ``line`` and at the place ``column`` gives for
        the pose's cell at fault (0 time, 1 x, 2 y)."""
        # with the pose before it: the order checks need both (that one passed already)
        poses = [(t, x, y, line)] if self.last_pose is None else [self.last_pose, (t, x, y, line)]
        numbers = np.array([pose[:3] for pose in poses], dtype=np.float64)
        lines = [pose[3] for pose in poses]
        found = sample_diagnostics(
            numbers[:, 0],
            numbers[:, 1],
            numbers[:, 2],
            file=None,
            lines=None if None in lines else [int(n) for n in lines if n is not None],
            first=self.samples - (len(poses) - 1),
            place=(
                None
                if column is None
                else lambda index, cell: column(cell) if index == len(poses) - 1 else {}
            ),
        )
        if found:
            raise UsageError(found)
        if self.previous_time is None:
            self.origin = t  # times in messages count from the first pose
        self.previous_time = t
        self.last_pose = (t, x, y, line)
        self.samples += 1
        before = len(self.reducer.kept)
        self.reducer.feed(np.array([[t, x, y]]))
        if len(self.reducer.kept) != before or self.last is None:
            self._advance()

    # -- the work -----------------------------------------------------------------------------

    def _advance(self) -> None:
        kept = self.reducer.kept
        stretch = np.vstack(([self.last] if self.last is not None else []) + kept)
        self.reducer.kept = []  # bounded: what is progressed is forgotten
        if len(stretch) > 1:
            self._check_workspace(stretch)
            pieces = build_pieces(
                stretch[:, 0], stretch[:, 1:], None, self.regions, self.convention
            )
            closed = self.convention == "closed"
            for k in range(len(pieces.is_point) - 1):  # the last point piece is the tail's
                inside = frozenset(
                    n for n, hit in zip(self.names, pieces.labels[k].tolist(), strict=True) if hit
                )
                piece = Piece(inside, point_rule=closed and bool(pieces.is_point[k]))
                self.residues = [progress(r, piece) for r in self.residues]
                self.task = progress(self.task, piece)
        elif self.workspace:
            self._check_workspace(stretch)
        self.last = stretch[-1]
        self._evaluate(float(stretch[-1, 0]))

    def _labels(self, point: FloatArray) -> tuple[frozenset[str], frozenset[str]]:
        """The last sample's labels and the unknown ones (the verifier's rule for a log's
        last point: on a boundary, under the right convention, where it goes next decides)."""
        position = point[None, 1:]
        if self.convention == "closed":
            hits = boundary_membership(self.shapes, list(self.regions.values()), position)[0]
            return frozenset(n for n, h in zip(self.names, hits.tolist(), strict=True) if h), (
                frozenset()
            )
        closed = region_membership(self.shapes, position, closed=True)[0]
        interior = region_membership(self.shapes, position, closed=False)[0]
        inside = frozenset(n for n, h in zip(self.names, closed.tolist(), strict=True) if h)
        unknown = frozenset(
            n
            for n, c, i in zip(self.names, closed.tolist(), interior.tolist(), strict=True)
            if c and not i
        )
        return inside, unknown

    def _tail(self) -> list[Piece]:
        assert self.last is not None
        inside, unknown = self._labels(self.last)
        closed = self.convention == "closed"
        head = Piece(inside, unknown, point_rule=closed)
        if self.reducer.pending is None:
            return [head]
        # Samples since the last kept one lie in its disc, in its cell: its labels throughout.
        cell = Piece(inside)
        return [Piece(inside, point_rule=closed), cell, Piece(inside, point_rule=closed)]

    def _evaluate(self, time: float) -> None:
        tail = self._tail()
        for conjunct, r in zip(self.conjuncts, self.residues, strict=True):
            self._set(time, to_text(conjunct), OUTCOMES[value(r, tail)])
        # the task's own verdict: final once satisfied or violated (LTL3); the workspace,
        # which an open log can break at any time, is its own line (see :attr:`outcome`)
        self._set(time, "task", OUTCOMES[value(self.task, tail)])

    def _set(self, time: float, subject: str, verdict: str, message: str | None = None) -> None:
        if self.verdicts.get(subject) != verdict:
            self.verdicts[subject] = verdict
            self.pending.append(Change(time, subject, verdict, message))

    def _check_workspace(self, stretch: FloatArray) -> None:
        if not self.workspace or self.excursion is not None:
            return
        from tlmpc.ltl.ast import TRUE

        piece = dataclasses.replace(
            self.trace,
            times=stretch[:, 0].copy(),
            points=stretch[:, 1:].copy(),
            formula=TRUE,
            regions={},
            ending="open",
            loop_start=None,
            origin=self.origin,
        )
        found = [v for v in verify_trace(piece).violations if v.conjunct == "workspace"]
        if found:
            first = found[0]
            when = float(first.time) if first.time is not None else float(stretch[0, 0])
            self.excursion = Change(when, "workspace", "violated", first.message)
            self._set(when, "workspace", "violated", first.message)

    # -- output -------------------------------------------------------------------------------

    def changes(self) -> list[Change]:
        """What changed since the last call, in order."""
        found, self.pending = self.pending, []
        return found

    def finish(self) -> list[Change]:
        """The last pending sample is the log's end: evaluate it as the log's last point."""
        if self.reducer.pending is not None and self.last is not None:
            self.reducer.kept.append(self.reducer.pending)
            self.reducer.pending = None
            self._advance()
        return self.changes()

    @property
    def start(self) -> float:
        """The first pose's time, which the times of messages count from (0 before it)."""
        return self.origin if self.origin is not None else 0.0

    @property
    def outcome(self) -> str:
        """The run's verdict so far, as ``tlmpc verify`` gives it: ``violated`` after a
        workspace violation, else the task's."""
        if self.excursion is not None:
            return "violated"
        return self.verdicts.get("task", "inconclusive")
