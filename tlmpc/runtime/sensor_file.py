"""Timed sensor readings from a CSV file, for ``tlmpc simulate OUT --sensors FILE``.

Two layouts, told apart by the header (docs/cli.md):

* **long** — header ``t,sensor,value``; one row per reading of one sensor;
* **wide** — header ``t`` then sensor names (every sensor of the mission once); one row per
  instant with every sensor's value.

Times are seconds from the start: finite, ``>= 0``, never decreasing; the readings at t = 0
must give every sensor's value (rows with one time are one instant).  Values are ``true``,
``false``, ``1`` or ``0`` (any case).  Lines starting with ``#`` and blank lines are skipped.
Each reading's value holds from its time until the next change (right-continuous).
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from pathlib import Path

from tlmpc.base.errors import Diagnostic, InvalidInputError, UsageError, error
from tlmpc.runtime.environments import Change

VALUES = {"true": True, "false": False, "1": True, "0": False}


def read_sensor_file(path: Path, sensors: Sequence[str]) -> list[Change]:
    """The changes of ``path``, one per instant with the full reading after it (the first at
    t = 0); U101 when the file cannot be read, U102-U104 (located) when it is malformed."""
    name = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise UsageError(
            error(
                "U101",
                f"cannot read the sensor file {name}: {reason}",
                hint="give a UTF-8 CSV file of timed readings (docs/cli.md, tlmpc simulate)",
                file=name,
            )
        ) from None
    rows = [
        (number, line)
        for number, line in enumerate(text.splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not rows:
        raise InvalidInputError(
            error(
                "U102",
                "the sensor file is empty",
                hint="start with a header: t,sensor,value (or t and the sensor names)",
                file=name,
                line=1,
                col=1,
            )
        )
    header_line, header_text = rows[0]
    header = _cells(header_text)
    if [cell for cell, _ in header] == ["t", "sensor", "value"]:
        timed = _long(rows[1:], sensors, name)
    else:
        timed = _wide(header_line, header, rows[1:], sensors, name)
    return _instants(timed, sensors, name)


def _cells(line: str) -> list[tuple[str, int]]:
    """The cells of a CSV line with the column each starts at (1-based)."""
    cells = next(csv.reader([line]))
    found, col = [], 1
    for cell in cells:
        found.append((cell.strip(), col))
        col += len(cell) + 1
    return found


def _fail(code: str, message: str, hint: str, name: str, line: int, col: int) -> InvalidInputError:
    return InvalidInputError(error(code, message, hint=hint, file=name, line=line, col=col))


def _time(cell: str, name: str, line: int, col: int) -> float:
    try:
        value = float(cell)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value < 0.0:
        raise _fail(
            "U103",
            f"time {cell!r} is not a number of seconds >= 0",
            "times count seconds from the start of the run, e.g. 0, 2.5",
            name,
            line,
            col,
        )
    return value


def _value(cell: str, sensor: str, name: str, line: int, col: int) -> bool:
    value = VALUES.get(cell.lower())
    if value is None:
        raise _fail(
            "U103",
            f"value {cell!r} of sensor {sensor!r} is not true, false, 1 or 0",
            "write each reading as true/false (or 1/0)",
            name,
            line,
            col,
        )
    return value


def _unknown(sensor: str, sensors: Sequence[str], name: str, line: int, col: int) -> None:
    if sensor not in sensors:
        raise _fail(
            "U102",
            f"{sensor!r} is not a sensor of the mission (its sensors: {', '.join(sensors)})",
            "name the mission's sensors exactly as in its sensors: section",
            name,
            line,
            col,
        )


Timed = list[tuple[float, int, str, bool]]  # (time, line, sensor, value)


def _long(rows: list[tuple[int, str]], sensors: Sequence[str], name: str) -> Timed:
    timed: Timed = []
    for number, line in rows:
        cells = _cells(line)
        if len(cells) != 3:
            raise _fail(
                "U103",
                f"a row has {len(cells)} cells, not 3 (t,sensor,value)",
                "one reading per row: time, sensor name, value",
                name,
                number,
                1,
            )
        (t_cell, t_col), (sensor, s_col), (v_cell, v_col) = cells
        t = _time(t_cell, name, number, t_col)
        _unknown(sensor, sensors, name, number, s_col)
        timed.append((t, number, sensor, _value(v_cell, sensor, name, number, v_col)))
    return timed


def _wide(
    header_line: int,
    header: list[tuple[str, int]],
    rows: list[tuple[int, str]],
    sensors: Sequence[str],
    name: str,
) -> Timed:
    header_cells = [cell for cell, _ in header]
    if not header_cells or header_cells[0] != "t":
        raise _fail(
            "U102",
            f"the header starts with {header_cells[0] if header_cells else ''!r}, not t",
            "write the header t,sensor,value (one reading per row) or t,<sensor>,<sensor>,...",
            name,
            header_line,
            1,
        )
    columns = header_cells[1:]
    for sensor, col in header[1:]:
        _unknown(sensor, sensors, name, header_line, col)
        if columns.count(sensor) > 1:
            raise _fail(
                "U102",
                f"sensor {sensor!r} has two columns",
                "give each sensor one column",
                name,
                header_line,
                col,
            )
    missing = [s for s in sensors if s not in columns]
    if missing:
        raise _fail(
            "U102",
            f"the header has no column for {', '.join(missing)}",
            "a wide file gives every sensor's value in every row",
            name,
            header_line,
            1,
        )
    timed: Timed = []
    for number, line in rows:
        cells = _cells(line)
        if len(cells) != len(header_cells):
            raise _fail(
                "U103",
                f"a row has {len(cells)} cells, the header {len(header_cells)}",
                "give the time and every sensor's value in each row",
                name,
                number,
                1,
            )
        t = _time(cells[0][0], name, number, cells[0][1])
        for sensor, (cell, at) in zip(columns, cells[1:], strict=True):
            timed.append((t, number, sensor, _value(cell, sensor, name, number, at)))
    return timed


def _instants(timed: Timed, sensors: Sequence[str], name: str) -> list[Change]:
    """Full readings per instant, in time order (times must not decrease)."""
    problems: list[Diagnostic] = []
    changes: list[Change] = []
    current: dict[str, bool] = {}
    read_now: dict[str, tuple[bool, int]] = {}  # this instant's readings, and their lines
    last = -math.inf
    for t, line, sensor, value in timed:
        if t != last:
            read_now = {}
        earlier = read_now.get(sensor)
        if earlier is not None and earlier[0] != value:
            problems.append(
                error(
                    "U104",
                    f"sensor {sensor!r} reads {str(earlier[0]).lower()} (line {earlier[1]}) and "
                    f"{str(value).lower()} at one instant, t={t:g}",
                    hint="one instant has one value per sensor: drop one reading, or give "
                    "the later one its own time",
                    file=name,
                    line=line,
                    col=1,
                )
            )
            break
        read_now[sensor] = (value, line)
        if t < last:
            problems.append(
                error(
                    "U104",
                    f"time {t:g} comes after time {last:g}",
                    hint="list the readings in time order",
                    file=name,
                    line=line,
                    col=1,
                )
            )
            break
        if not changes and t > 0.0:
            problems.append(
                error(
                    "U104",
                    f"the first readings are at t={t:g}, not 0",
                    hint="give every sensor's value at t = 0 (the start of the run)",
                    file=name,
                    line=line,
                    col=1,
                )
            )
            break
        current[sensor] = value
        reading = {s: current.get(s, False) for s in sensors}
        lines = tuple((read, row) for read, (_, row) in read_now.items())
        if changes and changes[-1].time == t:
            changes[-1] = Change(t, reading, changes[-1].line, lines)
        else:
            changes.append(Change(t, reading, line, lines))
        last = t
    if problems:
        raise InvalidInputError(problems)
    if not changes:
        raise InvalidInputError(
            error(
                "U104",
                "the sensor file has a header and no readings",
                hint="give every sensor's value at t = 0",
                file=name,
                line=1,
                col=1,
            )
        )
    at_start = {sensor for t, _, sensor, _ in timed if t == 0.0}
    missing = [s for s in sensors if s not in at_start]
    if missing:
        raise InvalidInputError(
            error(
                "U104",
                f"no reading of {', '.join(missing)} at t = 0",
                hint="give every sensor's value at t = 0 (the start of the run)",
                file=name,
                line=changes[0].line,
                col=1,
            )
        )
    return changes


__all__ = ["VALUES", "read_sensor_file"]
