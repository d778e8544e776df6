"""``tlmpc monitor --mission MISSION [LOG]``: verdicts of a running robot, live.

Reads poses from standard input or a log file (``--follow``: as it grows), prints each
conjunct's three-valued verdict whenever it changes, and at the end of the input exits with
the verdict's code (0 satisfied, 1 violated, 4 inconclusive; 2 for bad input).
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import math
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, TextIO

if TYPE_CHECKING:
    from tlmpc.base.errors import Diagnostic
    from tlmpc.fleet.monitor import Change
    from tlmpc.importers.logs import CsvLines, LogLines
    from tlmpc.mission.model import Mission

NAME = "monitor"
HELP = "watch a running robot's poses (stdin or a growing log) and print verdicts as they change"
DESCRIPTION = """\
Verify a live log against the task of --mission with the offline verifier's semantics (an
open log: satisfied, violated or inconclusive, per conjunct and for the whole task), printing
each verdict when it changes, at the time of the pose that changed it (counted from the first
pose, the pose's own stamp beside).  Poses come from standard input, or from LOG (with
--follow, as the file grows; only lines ended by a line break are read), as CSV lines (t,x,y
with or without a header, as `tlmpc verify` reads CSV logs) or JSON lines ({"t": ..., "x":
..., "y": ...}).  Memory stays bounded however long the robot runs.  At the end of the input,
exits 0 satisfied, 1 violated, 4 inconclusive."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument(
        "log", nargs="?", default="-", help="the log to read (default: standard input)"
    )
    parser.add_argument("--mission", type=Path, required=True, help="the mission file")
    parser.add_argument(
        "--boundary",
        choices=("right", "closed"),
        help="labelling convention (default: the mission's)",
    )
    parser.add_argument(
        "--follow", action="store_true", help="keep reading LOG as it grows (like tail -f)"
    )
    parser.add_argument(
        "--idle",
        type=float,
        metavar="SECONDS",
        help="with --follow: stop when LOG has not grown for SECONDS (default: never)",
    )
    parser.add_argument("--columns", metavar="TIME,X,Y", help="CSV: the time and position columns")
    parser.add_argument(
        "--transform", metavar="X,Y,YAW", help="map the poses' frame into the mission's"
    )
    parser.add_argument("--jsonl", action="store_true", help="print each change as a JSON line")


#: How often a followed file is polled for new lines.
POLL_SECONDS = 0.2

#: Bytes asked for at a time (a read returns what has come, a pipe's as soon as any has).
READ_BYTES = 1 << 16


def _lines(stream: IO[bytes], reader: LogLines, follow: bool, idle: float | None) -> Iterator[str]:
    """The lines of ``stream`` as they come; following, wait at its end for more, until it
    has not grown for ``idle`` seconds.  A last line without its line break is read at the
    end of the input, but not when following: it may still be being written, and is left in
    ``reader.rest``."""
    quiet_since = time.monotonic()
    while True:
        data = stream.read1(READ_BYTES)  # type: ignore[attr-defined]
        if data:
            quiet_since = time.monotonic()  # the input grew, whether or not a line ended
            yield from reader.feed(data)
            continue
        if not follow:
            break
        if idle is not None and time.monotonic() - quiet_since >= idle:
            break
        time.sleep(POLL_SECONDS)
    if not follow:
        yield from reader.finish()


def _line(change: Change, start: float, jsonl: bool) -> str:
    """A change as the monitor prints it; ``start``: the first pose's time, which every
    time printed counts from (the pose's own stamp beside, as ``tlmpc verify`` writes)."""
    from tlmpc.verify.clock import at, elapsed

    if jsonl:
        record: dict[str, Any] = {
            "t": elapsed(change.time, start),
            "stamp": change.time,
            "subject": change.subject,
            "verdict": change.verdict,
        }
        if change.message:
            record["message"] = change.message
        return json.dumps(record)
    text = f"{at(change.time, start)}  {change.subject}: {change.verdict}"
    return text + (f" ({change.message})" if change.message else "")


def _check_idle(idle: float | None) -> None:
    """Refuse (F011) an ``--idle`` that is negative or not a number."""
    from tlmpc.base.errors import UsageError, error

    if idle is not None and (math.isnan(idle) or idle < 0):
        raise UsageError(
            error(
                "F011",
                f"--idle must be a number of seconds >= 0, got {idle:g}",
                hint="for example --idle 30: stop when LOG has not grown for 30 s",
                file="<command line>",
            )
        )


@contextlib.contextmanager
def _opened(log: str) -> Iterator[IO[bytes]]:
    """The bytes of LOG (a regular file only: a FIFO or a device is refused at once, M050),
    or of standard input for ``-``."""
    from tlmpc.base.errors import UsageError, error
    from tlmpc.importers.logs import require_path
    from tlmpc.io.inputs import open_regular

    if log == "-":
        stdin = getattr(sys.stdin, "buffer", None)
        if stdin is None:
            raise UsageError(
                error(
                    "M050",
                    "there is no standard input to read",
                    hint="name the log: tlmpc monitor --mission MISSION LOG",
                    file="<stdin>",
                )
            )
        yield stdin
        return
    require_path(Path(log))
    with open_regular(Path(log), code="M050", what="log") as stream:
        yield stream


def _bound_place(mission: Mission) -> tuple[int | None, int | None]:
    """Where the first task phrase or ``ltl`` conjunct with a time bound is written."""
    from tlmpc.ltl.ast import bounded_operators
    from tlmpc.mission.parts import task_parts

    for part in task_parts(mission):
        if bounded_operators(part.formula):
            return part.line, part.col
    return None, None


def _at_mission(diagnostic: Diagnostic, mission: Mission, file: str) -> Diagnostic:
    """A refusal of the mission's task placed in the mission (F010: at the time bound)."""
    if diagnostic.file:
        return diagnostic
    line, col = _bound_place(mission) if diagnostic.code == "F010" else (None, None)
    return dataclasses.replace(diagnostic, file=file, line=line, col=col)


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Monitor until the input ends."""
    from tlmpc.base.errors import UsageError, error
    from tlmpc.fleet.monitor import Monitor
    from tlmpc.importers.logs import CsvLines, LogLines, parse_columns, parse_transform
    from tlmpc.io.report import OUTCOME_EXIT, Reporter
    from tlmpc.verify.trace_input import load_log_mission, positions_document

    report = Reporter.for_args(args, out, err)
    _check_idle(args.idle)
    name = "<stdin>" if args.log == "-" else args.log
    mission = load_log_mission(args.mission)
    try:
        monitor = Monitor(positions_document(mission), convention=args.boundary)
    except UsageError as exc:  # what the mission asks that the monitor cannot: the mission's
        file = mission.source or str(args.mission)
        raise UsageError([_at_mission(d, mission, file) for d in exc.diagnostics]) from None
    columns = parse_columns(args.columns) if args.columns else None
    transform = parse_transform(args.transform) if args.transform else None
    csv = CsvLines(name, columns)
    reader = LogLines(name)
    # Standard input needs no following: a read waits for the pipe's writer, and the pipe's
    # end is final (polling it again would wait forever).
    follow = args.follow and args.log != "-"
    with _opened(args.log) as stream:
        try:
            lines = _lines(stream, reader, follow, args.idle)
            for number, raw in enumerate(lines, start=1):
                pose = _pose(raw, csv, transform, name, number)
                if pose is None:
                    continue
                try:
                    monitor.add(*pose, line=number, column=_cell_place(raw, csv))
                except UsageError as exc:
                    raise UsageError(
                        [
                            d if d.file else dataclasses.replace(d, file=name)
                            for d in exc.diagnostics
                        ]
                    ) from None
                for change in monitor.changes():
                    report.stream(_line(change, monitor.start, args.jsonl))
        except OSError as exc:  # a read that fails (a disk error): the system's reason
            raise UsageError(
                error("M050", f"cannot read {name}: {exc.strerror or exc}", file=name)
            ) from None
    if reader.rest:
        report.note(
            f"{name}: stopped following with line {reader.count + 1} unfinished (no line "
            "break yet): it is left out"
        )
    if monitor.samples == 0:
        raise UsageError(
            error(
                "V002",
                "no poses were read",
                hint="the input held no pose line (only a header, comments or blank lines)",
                file=name,
            )
        )
    for change in monitor.finish():
        report.stream(_line(change, monitor.start, args.jsonl))
    text = "" if args.jsonl else f"{name}: {monitor.outcome} after {monitor.samples:,} poses\n"
    result = {"verdict": monitor.outcome, "poses": monitor.samples, "verdicts": monitor.verdicts}
    return report.finish(OUTCOME_EXIT[monitor.outcome], result, text)


def _pose(
    raw: str,
    csv: CsvLines,
    transform: tuple[float, float, float] | None,
    name: str,
    number: int,
) -> tuple[float, float, float] | None:
    """The pose on line ``number`` (a JSON or a CSV line) in the mission's frame; None for a
    blank, comment or header line."""
    import numpy as np

    from tlmpc.importers.logs import apply_transform

    pose = _json_pose(raw, name, number) if raw.lstrip().startswith("{") else csv.parse(raw, number)
    if pose is None or transform is None:
        return pose
    t, x, y = apply_transform(np.array([pose], dtype=np.float64), transform)[0].tolist()
    return t, x, y


def _cell_place(raw: str, csv: CsvLines) -> Callable[[int], dict[str, int]]:
    """Where the line ``raw`` writes a pose's cell (0 time, 1 x, 2 y): its column, found when
    a diagnostic needs it — the value of ``t``, ``x`` or ``y`` in a JSON line, the cell in a
    CSV line."""

    def place(cell: int) -> dict[str, int]:
        if raw.lstrip().startswith("{"):
            found = _json_value_column(raw, "txy"[cell])
            return {"col": found} if found is not None else {}
        column = csv.column(raw, cell)
        return {"col": column} if column is not None else {}

    return place


def _json_value_column(raw: str, key: str) -> int | None:
    """The column of the value of ``key`` in the JSON object on the line ``raw`` (of the
    object itself when it has no ``key``)."""
    from tlmpc.io.json_places import json_path, json_place

    found = json_place(raw, json_path(key))
    return found[1] if found is not None else None


def _json_pose(raw: str, name: str, number: int) -> tuple[float, float, float]:
    """The pose of a JSON line; its numbers read as a CSV cell is (an integer too large for
    a float is infinite, which the sample checks refuse as V003)."""
    from tlmpc.base.errors import UsageError, error

    col: int | None = None
    problem = ""
    try:
        record = json.loads(raw, parse_int=float)
        values = (record["t"], record["x"], record["y"])
        # numbers only: float() would also take "5", true and "1_0"
        wrong = [key for key, v in zip("txy", values, strict=True) if not isinstance(v, float)]
        if not wrong:
            return values[0], values[1], values[2]
        problem = f" ({wrong[0]} is not a number)"
        col = _json_value_column(raw, wrong[0])
    except json.JSONDecodeError as exc:
        col = exc.colno if exc.lineno == 1 else None
    except KeyError as exc:
        problem = f" (it has no {exc.args[0]})"
        col = _json_value_column(raw, exc.args[0])  # the object's own column
    except (ValueError, TypeError, RecursionError):
        pass
    raise UsageError(
        error(
            "M053",
            'a JSON line must be an object {"t": ..., "x": ..., "y": ...} of numbers' + problem,
            hint='for example {"t": 12.5, "x": 3.2, "y": 1.0}; correct or delete the line',
            file=name,
            line=number,
            col=col,
        )
    )
