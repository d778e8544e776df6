"""Environments for simulating a reactive mission: who changes the sensors, and when.

Every environment keeps the mission's assumptions (docs/semantics.md, "Executing a
strategy"): it never gives a reading that breaks a safety assumption, and the generated ones
meet every fairness assumption (and let the robot arrive where it heads) again within
:data:`FAIRNESS_BOUND` events.

* :class:`RandomEnvironment` changes the sensors at seeded random times to seeded random
  values among those the assumptions allow;
* :class:`AdversarialEnvironment` changes them as often as its minimum gap allows, to the
  reading after which the strategy's answer is worst for the robot: no progress on its
  recurrence goals, a new route; it grants fairness (and arrivals) only when the bound forces
  it;
* :class:`ScriptedEnvironment` replays timed readings from a CSV file
  (:mod:`tlmpc.runtime.sensor_file`), refusing those that break an assumption.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tlmpc.runtime.assumptions import AssumptionTracker, letter_of
from tlmpc.runtime.reactive import ReactiveExecutor

#: Every fairness assumption, and the robot's arrival, is granted within this many events.
FAIRNESS_BOUND = 6

Reading = dict[str, bool]


def readings(sensors: Sequence[str]) -> list[Reading]:
    """Every valuation of ``sensors``, in a fixed order (all off first)."""
    return [
        dict(zip(sensors, bits, strict=True))
        for bits in itertools.product((False, True), repeat=len(sensors))
    ]


@dataclass(frozen=True, slots=True)
class Change:
    """A reading the environment gives at ``time`` (``line``: where a file gave it, its first
    row at that time; ``lines``: the row of each sensor read at that time)."""

    time: float
    reading: Reading
    line: int | None = None
    lines: tuple[tuple[str, int], ...] = ()


class Environment:
    """The interface the closed loop drives (generated environments share the fairness
    bookkeeping)."""

    name = "environment"

    def __init__(self, sensors: Sequence[str]) -> None:
        self.sensors = tuple(sensors)
        self.all = readings(self.sensors)
        self._without_arrival = 0  # events since the robot last arrived (while it moved)

    def first(self, executor: ReactiveExecutor, tracker: AssumptionTracker) -> Change:
        """The reading at time 0."""
        raise NotImplementedError

    def next_change(self, executor: ReactiveExecutor, tracker: AssumptionTracker) -> float:
        """When the environment next changes a sensor (``inf``: not before an arrival)."""
        raise NotImplementedError

    def change(
        self, executor: ReactiveExecutor, tracker: AssumptionTracker, arriving: bool
    ) -> Change | None:
        """The reading now (at a change the environment scheduled, or with ``arriving`` at the
        robot's arrival); None: it keeps the sensors as they are."""
        raise NotImplementedError

    def observed(self, executor: ReactiveExecutor, arrived: bool) -> None:
        """Bookkeeping after each event."""
        if arrived or executor.staying:
            self._without_arrival = 0
        else:
            self._without_arrival += 1

    # --- shared by the generated environments --------------------------------------------

    def _allowed(
        self, executor: ReactiveExecutor, tracker: AssumptionTracker, face: int
    ) -> list[Reading]:
        regions = executor.face_regions(face)
        return [r for r in self.all if tracker.allows(letter_of(regions, _on(r)))]

    def _fair(
        self,
        executor: ReactiveExecutor,
        tracker: AssumptionTracker,
        face: int,
        candidates: list[Reading],
    ) -> list[Reading]:
        """The candidates that meet the most overdue fairness assumptions, when any is due."""
        waiting = tracker.waiting()
        due = [i for i, w in enumerate(waiting) if w + 1 >= FAIRNESS_BOUND]
        if not due:
            return candidates
        regions = executor.face_regions(face)
        scored = [
            (sum(tracker.fulfils(letter_of(regions, _on(r)))[i] for i in due), r)
            for r in candidates
        ]
        best = max((s for s, _ in scored), default=0)
        return [r for s, r in scored if s == best] if best > 0 else candidates

    def _must_let_arrive(self, executor: ReactiveExecutor) -> bool:
        return not executor.staying and self._without_arrival + 1 >= FAIRNESS_BOUND


def _on(reading: Reading) -> list[str]:
    return [name for name, value in reading.items() if value]


def time_scale(executor: ReactiveExecutor) -> float:
    """The time the robot takes to cross a typical triangle at full speed."""
    abstraction = executor.abstraction
    corners = abstraction.vertices[abstraction.triangles]
    spans = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    return float(np.median(spans)) / executor.mission.robot.max_speed


class RandomEnvironment(Environment):
    """Seeded random readings at seeded random times, within the assumptions."""

    name = "random"

    def __init__(self, sensors: Sequence[str], seed: int, scale: float) -> None:
        super().__init__(sensors)
        self.rng = np.random.default_rng(seed)
        self.scale = scale

    def first(self, executor: ReactiveExecutor, tracker: AssumptionTracker) -> Change:
        options = self._allowed(executor, tracker, executor.face)
        return Change(0.0, self._pick(options) if options else dict.fromkeys(self.sensors, False))

    def next_change(self, executor: ReactiveExecutor, tracker: AssumptionTracker) -> float:
        if self._must_let_arrive(executor) or not self.sensors:
            return math.inf
        # Between a tenth of a triangle's crossing and a few triangles' crossings.
        return executor.time + self.scale * float(self.rng.uniform(0.1, 4.0))

    def change(
        self, executor: ReactiveExecutor, tracker: AssumptionTracker, arriving: bool
    ) -> Change | None:
        face = executor.face
        options = self._allowed(executor, tracker, face)
        current = executor.sensors
        if arriving and current in options and self.rng.random() < 0.7:
            options = [current]  # most arrivals leave the sensors alone
        else:
            different = [r for r in options if r != current]
            options = different or options
        options = self._fair(executor, tracker, face, options)
        if not options:
            return None
        reading = self._pick(options)
        return None if reading == current else Change(executor.time, reading)

    def _pick(self, options: list[Reading]) -> Reading:
        return options[int(self.rng.integers(len(options)))]


class AdversarialEnvironment(Environment):
    """The reading the strategy likes least, as often as every ``gap`` seconds."""

    name = "adversarial"

    def __init__(self, sensors: Sequence[str], seed: int, gap: float) -> None:
        super().__init__(sensors)
        self.rng = np.random.default_rng(seed)
        self.gap = gap

    def first(self, executor: ReactiveExecutor, tracker: AssumptionTracker) -> Change:
        options = self._allowed(executor, tracker, executor.face)
        if not options:
            return Change(0.0, dict.fromkeys(self.sensors, False))
        starts = [r for r in options if executor.machine.start(r, executor.face) is not None]
        return Change(0.0, self._worst(executor, starts or options, first=True))

    def next_change(self, executor: ReactiveExecutor, tracker: AssumptionTracker) -> float:
        if self._must_let_arrive(executor) or not self.sensors:
            return math.inf
        return executor.time + self.gap

    def change(
        self, executor: ReactiveExecutor, tracker: AssumptionTracker, arriving: bool
    ) -> Change | None:
        face = executor.face
        options = self._fair(executor, tracker, face, self._allowed(executor, tracker, face))
        if not options:
            return None
        reading = self._worst(executor, options, moved=arriving)
        return None if reading == executor.sensors else Change(executor.time, reading)

    def _worst(
        self,
        executor: ReactiveExecutor,
        options: list[Reading],
        *,
        moved: bool = False,
        first: bool = False,
    ) -> Reading:
        """The reading whose answer keeps the robot's goal counter where it is, sends it on
        a new route, and switches the most actions (seeded ties)."""
        machine = executor.machine

        def score(reading: Reading) -> tuple[int, int, int, float]:
            if first:
                node = machine.start(reading, executor.face)
            else:
                node = machine.answer(executor.node, reading, executor.face, moved)
            if node is None:
                return (-1, 0, 0, 0.0)
            held = 1 if first or machine.counters[node] == machine.counters[executor.node] else 0
            rerouted = 1 if first or machine.goal(node) != executor.goal else 0
            switched = sum(
                machine.action_values(node)[a] != executor.actions.get(a) for a in machine.actions
            )
            return (held, rerouted, switched, float(self.rng.random()))

        return max(options, key=score)


class ScriptedEnvironment(Environment):
    """Readings replayed from a file, each at its time."""

    name = "file"

    def __init__(self, sensors: Sequence[str], changes: Sequence[Change], source: str) -> None:
        super().__init__(sensors)
        self.changes = list(changes)
        self.source = source
        self._next = 1

    def first(self, executor: ReactiveExecutor, tracker: AssumptionTracker) -> Change:
        return self.changes[0]

    def next_change(self, executor: ReactiveExecutor, tracker: AssumptionTracker) -> float:
        if self._next < len(self.changes):
            return self.changes[self._next].time
        return math.inf

    def change(
        self, executor: ReactiveExecutor, tracker: AssumptionTracker, arriving: bool
    ) -> Change | None:
        if self._next < len(self.changes) and self.changes[self._next].time <= executor.time:
            change = self.changes[self._next]
            self._next += 1
            return change
        return None


__all__ = [
    "FAIRNESS_BOUND",
    "AdversarialEnvironment",
    "Change",
    "Environment",
    "RandomEnvironment",
    "ScriptedEnvironment",
    "readings",
    "time_scale",
]
