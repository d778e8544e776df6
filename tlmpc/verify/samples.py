"""Checks on a log's parsed samples (times and positions), whatever file they came from.

Every reader of trajectories (trace.json, CSV, recorded bags) hands its arrays to
:func:`check_samples` before verification, so every log source gets the same diagnostics:
no samples (V002), a non-finite value (V003), time going backwards (V005), repeated time
stamps (V020), a time or coordinate beyond 1e12 (V024).  All problems are reported at once
(a few of each kind), with the source line of each sample when the reader knows it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from tlmpc.base.errors import Diagnostic, UsageError, error

FloatArray = npt.NDArray[np.float64]

#: At most this many diagnostics of one kind (a broken log can have thousands).
MAX_PER_KIND = 3

#: Times (seconds) and coordinates (the mission's units, at most 1e9 by its schema) beyond this
#: are refused (V024): a corrupt sample, whose differences would overflow to infinity.
MAX_MAGNITUDE = 1e12


#: Where a sample's cell is written, for a reader that knows more than its line: given the
#: sample's index (counted in the samples checked) and the cell (0 time, 1 x, 2 y), the fields
#: of the diagnostic that place it — ``col`` (a CSV cell's column), or ``path`` (the JSON path
#: of a trace's number, placed in its text by the trace reader).
CellPlace = Callable[[int, int], Mapping[str, Any]]

#: Where a sample came from, in words, for a log with no lines (a bag: the topic, number and
#: log time of its message): given the sample's index in its log (``first`` counted in), the
#: words said after the sample's number.
SampleOrigin = Callable[[int], str]


#: Said after the hint of a sample placed by its :data:`SampleOrigin`, whose two numbers differ.
_ORIGIN_NOTE = (
    "samples are counted from 0 in time order, a bag's messages from 1 in the order it "
    "stores them on their topic"
)


def _hint(hint: str, origin: SampleOrigin | None) -> str:
    return f"{hint} ({_ORIGIN_NOTE})" if origin is not None else hint


def _where(
    index: int, lines: Sequence[int] | None, first: int, origin: SampleOrigin | None = None
) -> tuple[str, int | None]:
    if lines is not None and index < len(lines):
        return f"sample {first + index} (line {lines[index]})", lines[index]
    if origin is not None:
        return f"sample {first + index} ({origin(first + index)})", None
    return f"sample {first + index}", None


def _at(place: CellPlace | None, index: int, cell: int) -> Mapping[str, Any]:
    return place(index, cell) if place is not None else {}


def sample_diagnostics(
    t: FloatArray,
    x: FloatArray,
    y: FloatArray,
    *,
    file: str | None,
    lines: Sequence[int] | None = None,
    first: int = 0,
    place: CellPlace | None = None,
    origin: SampleOrigin | None = None,
) -> list[Diagnostic]:
    """Every problem with the samples ``(t[i], x[i], y[i])`` (empty list: they are usable);
    ``first``: the number of the first of them in its log (a live log's samples come one by
    one); ``place``: where the offending cell of a sample is written (see :data:`CellPlace`);
    ``origin``: where a sample without a line came from (see :data:`SampleOrigin`)."""
    found: list[Diagnostic] = []
    if len(t) == 0:
        return [
            error(
                "V002",
                "the trace has no samples",
                hint="record at least one sample (t, x, y)",
                file=file,
            )
        ]
    values = np.column_stack([t, x, y])
    bad = np.flatnonzero(~np.all(np.isfinite(values), axis=1))
    for index in bad[:MAX_PER_KIND].tolist():
        what, line = _where(index, lines, first, origin)
        cells = np.flatnonzero(~np.isfinite(values[index])).tolist()
        found.append(
            error(
                "V003",
                f"{what} has a non-finite {'/'.join('txy'[c] for c in cells)} (NaN or infinity)",
                hint=_hint(
                    "drop or repair the sample; the verifier does not guess missing values",
                    origin,
                ),
                file=file,
                line=line,
                **_at(place, index, cells[0]),
            )
        )
    if len(bad):
        return found  # order checks on NaN times would only repeat the same rows
    far = np.flatnonzero(np.any(np.abs(values) > MAX_MAGNITUDE, axis=1))
    for index in far[:MAX_PER_KIND].tolist():
        what, line = _where(index, lines, first, origin)
        cell = int(np.flatnonzero(np.abs(values[index]) > MAX_MAGNITUDE)[0])
        found.append(
            error(
                "V024",
                f"{what} has a time or coordinate beyond {MAX_MAGNITUDE:g} "
                f"({', '.join(f'{v:g}' for v in values[index].tolist())})",
                hint=_hint(
                    "a corrupt sample, or times in nanoseconds: times are seconds and "
                    "positions the mission's units",
                    origin,
                ),
                file=file,
                line=line,
                **_at(place, index, cell),
            )
        )
    if len(far):
        return found  # differences of such values overflow
    steps = np.diff(t)
    for index in (np.flatnonzero(steps < 0)[:MAX_PER_KIND] + 1).tolist():
        what, line = _where(index, lines, first, origin)
        found.append(
            error(
                "V005",
                f"time goes backwards at {what}: t = {t[index - 1]:g} then {t[index]:g}",
                hint=_hint(
                    "sort the samples by time (the verifier does not reorder a log)",
                    origin,
                ),
                file=file,
                line=line,
                **_at(place, index, 0),
            )
        )
    repeated = np.flatnonzero(steps == 0) + 1
    for index in repeated[:MAX_PER_KIND].tolist():
        what, line = _where(index, lines, first, origin)
        same = bool(x[index] == x[index - 1] and y[index] == y[index - 1])
        found.append(
            error(
                "V020",
                f"{what} repeats the time stamp t = {t[index]:g} "
                + ("(same position)" if same else "at a different position")
                + (f"; {len(repeated)} repeated time stamps in all" if len(repeated) > 1 else ""),
                hint=_hint(
                    "drop duplicate samples; two positions at one instant are not a trajectory",
                    origin,
                ),
                file=file,
                line=line,
                **_at(place, index, 0),
            )
        )
    return found


#: The kinds of sample problems in the order :func:`sample_diagnostics` reports them; a
#: sample that is not finite (V003) leaves out every later kind, one too large (V024) the
#: order checks (their differences would only repeat it, or overflow).
_KINDS = ("V002", "V003", "V024", "V005", "V020")
_LEAVES_OUT = {"V003": ("V024", "V005", "V020"), "V024": ("V005", "V020")}


def as_whole_log(found: Sequence[Diagnostic]) -> list[Diagnostic]:
    """The problems :func:`sample_diagnostics` reports for a whole log, from those it found
    in its pieces (a log checked chunk by chunk): the kinds a problem leaves out are dropped,
    and the rest come kind by kind, each in the log's order."""
    for kind, leaves_out in _LEAVES_OUT.items():
        if any(d.code == kind for d in found):
            found = [d for d in found if d.code not in leaves_out]
    return sorted(found, key=lambda d: _KINDS.index(d.code))


def check_samples(
    t: FloatArray,
    x: FloatArray,
    y: FloatArray,
    *,
    file: str | None,
    lines: Sequence[int] | None = None,
    place: CellPlace | None = None,
    origin: SampleOrigin | None = None,
) -> None:
    """Raise :class:`UsageError` (exit 2) with every problem of the samples, if any."""
    found = sample_diagnostics(t, x, y, file=file, lines=lines, place=place, origin=origin)
    if found:
        raise UsageError(found)
