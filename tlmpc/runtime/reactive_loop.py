"""The closed loop of a reactive mission: an environment, the executor, and the trace.

Events follow docs/semantics.md ("Executing a strategy"): at an event the environment moves
first (new sensor values, or the robot's arrival in the face it heads for, or both at one
instant), the assumptions are checked on the new letter, and the robot answers at once.  The
run lasts a number of events, never a number of seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from tlmpc.base.errors import InvalidInputError, UsageError, error
from tlmpc.ltl.printer import to_text
from tlmpc.mission.model import TaskPart
from tlmpc.runtime.assumptions import AssumptionTracker, letter_of
from tlmpc.runtime.environments import Change, Environment, ScriptedEnvironment
from tlmpc.runtime.reactive import ReactiveExecutor

#: How many events a run lasts unless told otherwise.
DEFAULT_EVENTS = 200
#: The environment's scheduled changes that change nothing, in a row, before a resting robot's
#: run ends (it would rest for ever).
MAX_IDLE = 64


@dataclass(frozen=True)
class ReactiveRun:
    """A finished run: its trace document, its events, and why it stopped (``events``: the
    budget was spent; ``rest``: the robot stays and nothing will change any more)."""

    trace: dict[str, Any]
    executor: ReactiveExecutor
    stopped: str


def run_reactive(
    executor: ReactiveExecutor, environment: Environment, *, events: int = DEFAULT_EVENTS
) -> ReactiveRun:
    """Play ``environment`` against the executor for ``events`` events (after the start)."""
    tracker = AssumptionTracker(executor.mission)
    first = environment.first(executor, tracker)
    _read(executor, tracker, environment, first, executor.face)
    if not executor.start(first.reading):
        raise _no_answer(executor, first, environment)
    environment.observed(executor, arrived=False)
    pending = environment.next_change(executor, tracker)
    stopped = "events"
    idle = 0  # scheduled changes in a row that changed nothing
    while len(executor.events) <= events:
        stutter = executor.stutter_answer()
        stutter_at = math.inf
        if stutter is not None and tracker.allows(_letter(executor, executor.sensors)):
            stutter_at = executor.events[-1].time + executor.dwell_time()
        horizon = min(pending, stutter_at)
        if math.isinf(horizon) and executor.staying:
            stopped = "rest"
            break
        arrived = executor.advance(horizon)
        if arrived:
            change = environment.change(executor, tracker, arriving=True)
            reading = change.reading if change is not None else executor.sensors
            _read(executor, tracker, environment, change, executor.face, reading)
            if not executor.react(reading, arrived=True):
                raise _no_answer(executor, change, environment)
        elif executor.time >= pending:
            change = environment.change(executor, tracker, arriving=False)
            if change is None or change.reading == executor.sensors:
                idle += 1
                if idle >= MAX_IDLE and executor.staying and stutter is None:
                    stopped = "rest"  # the environment has nothing left to change
                    break
                pending = environment.next_change(executor, tracker)
                continue  # nothing changed: not an event
            _read(executor, tracker, environment, change, executor.face)
            if not executor.react(change.reading, arrived=False):
                raise _no_answer(executor, change, environment)
        else:
            assert stutter is not None
            tracker.read(_letter(executor, executor.sensors))
            executor.stutter(stutter)
        idle = 0
        environment.observed(executor, arrived)
        pending = environment.next_change(executor, tracker)
    if stopped == "rest":
        # Show the robot settling where it rests.
        executor.advance(executor.time + 4.0 * executor.dwell_time())
    return ReactiveRun(trace_document(executor), executor, stopped)


def _letter(executor: ReactiveExecutor, reading: dict[str, bool]) -> frozenset[str]:
    return letter_of(executor.face_regions(), [s for s, v in reading.items() if v])


def _breaking_line(change: Change | None, broken: TaskPart) -> int | None:
    """The sensor file's line of the reading that breaks ``broken``: the first row of the
    instant that reads a sensor the assumption names (else the instant's first row)."""
    if change is None:
        return None
    named = broken.formula.props()
    rows = [row for sensor, row in change.lines if sensor in named]
    return min(rows) if rows else change.line


def _read(
    executor: ReactiveExecutor,
    tracker: AssumptionTracker,
    environment: Environment,
    change: Change | None,
    face: int,
    reading: dict[str, bool] | None = None,
) -> None:
    """Check the new letter against the assumptions and read it (Q120/Q121 when broken)."""
    values = reading if reading is not None else (change.reading if change else executor.sensors)
    letter = letter_of(executor.face_regions(face), [s for s, v in values.items() if v])
    broken = tracker.broken_by(letter)
    if broken is None:
        tracker.read(letter)
        return
    shown = ", ".join(f"{s}={'true' if v else 'false'}" for s, v in values.items()) or "-"
    where = " and ".join(executor.face_regions(face)) or "free space (no region)"
    when = change.time if change is not None else executor.time
    if isinstance(environment, ScriptedEnvironment):
        raise InvalidInputError(
            error(
                "Q120",
                f"at t={when:g} the readings {shown}, with the robot in {where}, break the "
                f"assumption {broken.text!r}",
                hint="the sensor file must keep the mission's assumptions: change the reading, "
                "or its time (the robot's position at that time is the simulation's)",
                file=environment.source,
                line=_breaking_line(change, broken),
                col=1 if change is not None and change.line is not None else None,
            )
        )
    raise InvalidInputError(
        error(
            "Q121",
            f"at t={when:g} no sensor reading keeps the assumption {broken.text!r} with the "
            f"robot in {where}",
            hint="the assumptions constrain the robot's position in a way no environment can "
            "keep once the robot arrives there; state them on the sensors",
            file=executor.mission.source,
            line=broken.line,
            col=broken.col,
        )
    )


def _no_answer(
    executor: ReactiveExecutor, change: Change | None, environment: Environment
) -> UsageError:
    when = change.time if change is not None else executor.time
    diagnostic = error(
        "Q122",
        f"at t={when:g} the strategy has no answer to the readings "
        f"{change.reading if change else executor.sensors} in face {executor.face}",
        hint="the readings keep the assumptions, so strategy.json does not belong to this "
        "mission: compile it again",
        file=environment.source if isinstance(environment, ScriptedEnvironment) else None,
        line=change.line if change is not None else None,
    )
    return UsageError(diagnostic)


def trace_document(executor: ReactiveExecutor) -> dict[str, Any]:
    """``trace.json`` of a reactive run: positions, sensor and action signals, the task as
    the guarantee and the assumptions; the run may go on (``end: open``)."""
    from tlmpc.simulate.exact import trace_header

    mission = executor.mission
    assert mission.reactive is not None
    motion = executor.motion
    start = motion.times[0]
    signals = {
        name: [[start, points[0][1]], *points[1:]] if points[0][0] != start else points
        for name, points in executor.signals.items()
    }
    return {
        **trace_header(mission, mission.robot.max_speed),
        "points": [[t, x, y] for t, (x, y) in zip(motion.times, motion.points, strict=True)],
        "loop_start": None,
        "end": "open",
        "triangles": list(motion.triangles),
        "crossings": list(motion.crossings),
        # in the mission file's order, as the strategy's game declares them
        "sensors": list(executor.machine.sensors),
        "actions": list(executor.machine.actions),
        "assumptions": [to_text(part.formula) for part in mission.reactive.assumptions],
        "signals": signals,
    }


__all__ = ["DEFAULT_EVENTS", "ReactiveRun", "run_reactive", "trace_document"]
