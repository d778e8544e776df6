"""Sensor and action values of a reactive run: piecewise-constant, right-continuous signals.

A signal is a list of change points ``(t, value)`` in increasing time: the value holds from its
``t`` until the next change (so at the instant of a change the new value already holds).
Before its first change point a signal is *unknown* (a log whose sensor topic starts late),
and the verifier's three-valued evaluation treats it so.

The verifier cuts the continuous run at every instant where a signal changes, by adding a
sample there on the straight segment the robot is on (the path does not change), so that each
piece of the run has one value of every signal: the value at the piece's first instant.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from tlmpc.base.errors import Diagnostic, UsageError, error
from tlmpc.io.inputs import brief
from tlmpc.io.json_places import json_path

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]
IntArray = npt.NDArray[np.int64]

#: At most this many problems of one kind are listed per signal.
MAX_LISTED = 5


@dataclass(frozen=True, slots=True)
class Signal:
    """Change points of one proposition: ``values[i]`` holds from ``times[i]`` on."""

    name: str
    times: FloatArray = field(compare=False)
    values: BoolArray = field(compare=False)

    def at(self, instants: FloatArray) -> tuple[BoolArray, BoolArray]:
        """``(value, unknown)`` at each of ``instants`` (right-continuous; unknown before the
        first change point)."""
        index = np.searchsorted(self.times, instants, side="right") - 1
        unknown = index < 0
        value = np.where(unknown, False, self.values[np.maximum(index, 0)])
        return value.astype(bool), unknown


#: The words a boolean sample may be written as (after stripping and lower-casing).
WORDS = {"true": True, "false": False, "1": True, "0": False, "1.0": True, "0.0": False}


def as_boolean(value: Any) -> bool | None:
    """``True``/``False`` for a boolean sample (true/false/1/0, any case), None otherwise."""
    if isinstance(value, str):
        return WORDS.get(value.strip().lower())
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | float | np.integer | np.floating):
        return True if value == 1 else False if value == 0 else None
    return None


@dataclass(frozen=True, slots=True)
class Where:
    """Where each sample of a signal came from, for diagnostics."""

    file: str | None
    #: the line (CSV) of each sample, or None
    lines: Sequence[int] | None = None
    #: the JSON path or the bag topic the samples are under
    path: str | None = None
    #: a bag's message of each sample, in words (given the sample's index), or None
    origin: Callable[[int], str] | None = field(default=None, compare=False)

    def cell(self, index: int, cell: int) -> str | None:
        """The JSON path of cell ``cell`` (0 time, 1 value) of sample ``index``, when the
        samples are the ``[t, value]`` rows of a JSON array (else :attr:`path` as it is)."""
        if self.lines is None and self.path is not None and self.path.startswith("$"):
            return f"{self.path}[{index}][{cell}]"
        return self.path

    def sample(self, index: int) -> tuple[str, int | None]:
        """Words for sample ``index``, and its line."""
        if self.lines is not None and index < len(self.lines):
            return f"sample {index} (line {self.lines[index]})", self.lines[index]
        if self.origin is not None:
            return f"sample {index} ({self.origin(index)})", None
        return f"sample {index}" + (f" at {self.path}" if self.path else ""), None


def make_signal(name: str, times: Sequence[Any], values: Sequence[Any], where: Where) -> Signal:
    """Check the samples of ``name`` and keep its change points.

    Refuses (V030) a value that is not a boolean, (V031) a time that is not a finite number or
    does not increase — every problem at once, each with its sample (and line)."""
    found: list[Diagnostic] = []
    words = [as_boolean(v) for v in values]
    if None not in words and all(type(t) is float or type(t) is int for t in times):
        # the common case, without per-sample bookkeeping
        with contextlib.suppress(OverflowError):  # an integer too large: said where below
            clock = np.asarray(times, dtype=np.float64)
            if np.isfinite(clock).all():
                return _increasing(name, clock, np.asarray(words, dtype=bool), where, found)
    clock, bits = _checked(name, times, values, where, found)  # says where and why
    return _increasing(name, clock, bits, where, found)


def _checked(
    name: str, times: Sequence[Any], values: Sequence[Any], where: Where, found: list[Diagnostic]
) -> tuple[FloatArray, BoolArray]:
    """Sample by sample: each value a boolean (V030), each time a finite number (V031)."""
    clock = np.full(len(times), np.nan)
    bits = np.zeros(len(values), dtype=bool)
    for index, (t, v) in enumerate(zip(times, values, strict=True)):
        bit = as_boolean(v)
        if bit is None and sum(d.code == "V030" for d in found) < MAX_LISTED:
            what, line = where.sample(index)
            found.append(
                error(
                    "V030",
                    f"signal {name!r}, {what}: {brief(v)} is not a boolean",
                    hint="sensor and action values are true/false (or 1/0)",
                    file=where.file,
                    line=line,
                    path=where.cell(index, 1),
                )
            )
        bits[index] = bool(bit)
        number = _finite_time(t)
        if number is None:
            if sum(d.code == "V031" for d in found) < MAX_LISTED:
                what, line = where.sample(index)
                found.append(
                    error(
                        "V031",
                        f"signal {name!r}, {what}: time {brief(t)} is not a finite number",
                        hint="a signal's times are finite numbers of seconds, increasing",
                        file=where.file,
                        line=line,
                        path=where.cell(index, 0),
                    )
                )
            continue
        clock[index] = number
    return clock, bits


def _finite_time(value: Any) -> float | None:
    """``value`` as a finite time, or None (not a number, not finite, too large a float)."""
    if not isinstance(value, int | float) or isinstance(value, bool):
        return None
    try:
        number = float(value)
    except OverflowError:  # an integer beyond any float
        return None
    return number if math.isfinite(number) else None


def _increasing(
    name: str, clock: FloatArray, bits: BoolArray, where: Where, found: list[Diagnostic]
) -> Signal:
    """Refuse (V031) a time that does not come after the one before; the change points."""
    if not found:
        steps = np.flatnonzero(np.diff(clock) <= 0)
        for index in steps[:MAX_LISTED].tolist():
            what, line = where.sample(index + 1)
            found.append(
                error(
                    "V031",
                    f"signal {name!r}, {what}: time {clock[index + 1]:.9g} does not come after "
                    f"the previous sample's {clock[index]:.9g}",
                    hint="a signal's samples are in strictly increasing time",
                    file=where.file,
                    line=line,
                    path=where.cell(index + 1, 0),
                )
            )
    if found:
        raise UsageError(found)
    return changes(name, clock, bits)


def changes(name: str, times: FloatArray, values: BoolArray) -> Signal:
    """The signal of samples ``(times, values)`` (sorted), keeping only its change points."""
    keep = np.ones(len(values), dtype=bool)
    keep[1:] = values[1:] != values[:-1]
    return Signal(name, np.asarray(times[keep], dtype=np.float64), values[keep].copy())


def signals_of_document(
    document: Mapping[str, Any], names: Sequence[str], file: str | None
) -> dict[str, Signal]:
    """The ``signals`` of a trace document: name -> ``[[t, value], ...]`` (V033 when it is not
    that shape or names something that is neither a sensor nor an action)."""
    raw = document.get("signals")
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise UsageError(
            error(
                "V033",
                "`signals` is not an object of name -> [[t, value], ...]",
                hint='write the signals as {"alarm": [[0, false], [3.5, true]], ...}',
                file=file,
                path=json_path("signals"),
            )
        )
    found: dict[str, Signal] = {}
    for name, points in raw.items():
        path = json_path("signals", name)
        if name not in names:
            raise UsageError(
                error(
                    "V033",
                    f"signal {name!r} is neither a sensor nor an action of the trace",
                    hint="list it under `sensors` or `actions`",
                    file=file,
                    path=path,
                )
            )
        if (
            not isinstance(points, list)
            or not points
            or not all(isinstance(p, list | tuple) and len(p) == 2 for p in points)
        ):
            raise UsageError(
                error(
                    "V033",
                    f"signal {name!r} is not a non-empty list of [t, value] change points",
                    hint="write it as [[t, value], ...], e.g. [[0, false], [3.5, true]]",
                    file=file,
                    path=path,
                )
            )
        found[name] = make_signal(
            name, [p[0] for p in points], [p[1] for p in points], Where(file, path=path)
        )
    return found


def with_cuts(
    times: FloatArray, points: FloatArray, cuts: FloatArray
) -> tuple[FloatArray, FloatArray, IntArray]:
    """The samples with one more at each instant of ``cuts`` strictly between two samples
    (on the straight segment there: the path is the same), and where each old sample went."""
    inside = cuts[(cuts > times[0]) & (cuts < times[-1])]
    inside = np.setdiff1d(inside, times)  # sorted, unique, none at a sample
    if not len(inside):
        return times, points, np.arange(len(times), dtype=np.int64)
    x = np.interp(inside, times, points[:, 0])
    y = np.interp(inside, times, points[:, 1])
    all_times = np.concatenate([times, inside])
    order = np.argsort(all_times, kind="stable")
    merged_points = np.concatenate([points, np.column_stack([x, y])])[order]
    where = np.empty(len(all_times), dtype=np.int64)
    where[order] = np.arange(len(all_times), dtype=np.int64)
    return all_times[order], merged_points, where[: len(times)]


def counted_from(signals: Mapping[str, Signal], zero: float) -> dict[str, Signal]:
    """``signals`` with their times counted from ``zero`` (the log's first sample, as the
    verifier counts every time)."""
    return {
        name: Signal(signal.name, signal.times - zero, signal.values)
        for name, signal in signals.items()
    }


def change_times(signals: Mapping[str, Signal]) -> FloatArray:
    """Every instant at which some signal changes (its first point included: from unknown)."""
    if not signals:
        return np.zeros(0)
    return np.unique(np.concatenate([s.times for s in signals.values()]))


def signal_labels(
    signals: Mapping[str, Signal], names: Sequence[str], starts: FloatArray
) -> tuple[BoolArray, BoolArray]:
    """(pieces × names) values and unknowns of the signals at the pieces' first instants.

    A name without a signal (an action the log does not carry) is unknown throughout."""
    values = np.zeros((len(starts), len(names)), dtype=bool)
    unknown = np.ones((len(starts), len(names)), dtype=bool)
    for column, name in enumerate(names):
        signal = signals.get(name)
        if signal is not None:
            values[:, column], unknown[:, column] = signal.at(starts)
    return values, unknown
