"""``tlmpc monitor --mission MISSION [LOG]``: verdicts of a running robot, live.

Reads poses from standard input or a log file (``--follow``: as it grows), prints each
conjunct's three-valued verdict whenever it changes, and at the end of the input exits with
the verdict's code (0 satisfied, 1 violated, 4 inconclusive; 2 for bad input).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

if TYPE_CHECKING:
    from tlmpc.fleet.monitor import Change

NAME = "monitor"
HELP = "watch a running robot's poses (stdin or a growing log) and print verdicts as they change"
DESCRIPTION = """\
Verify a live log against the task of --mission with the offline verifier's semantics (an
open log: satisfied, violated or inconclusive, per conjunct and for the whole task), printing
each verdict when it changes.  Poses come from standard input, or from LOG (with --follow, as
the file grows), as CSV lines (t,x,y with or without a header, as `tlmpc verify` reads CSV
logs) or JSON lines ({"t": ..., "x": ..., "y": ...}).  Memory stays bounded however long the
robot runs.  At the end of the input, exits 0 satisfied, 1 violated, 4 inconclusive."""


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


def _lines(stream: TextIO, follow: bool, idle: float | None) -> Iterator[str]:
    """Complete lines of ``stream``; following, wait for more at its end."""
    partial = ""
    quiet_since = time.monotonic()
    while True:
        chunk = stream.readline()
        if chunk:
            partial += chunk
            if partial.endswith("\n"):
                yield partial
                partial = ""
                quiet_since = time.monotonic()
            continue
        if not follow:
            break
        if idle is not None and time.monotonic() - quiet_since >= idle:
            break
        time.sleep(POLL_SECONDS)
    if partial:
        yield partial


def _line(change: Change, jsonl: bool) -> str:
    if jsonl:
        record = {"t": change.time, "subject": change.subject, "verdict": change.verdict}
        if change.message:
            record["message"] = change.message
        return json.dumps(record)
    text = f"t={change.time:.6g} s  {change.subject}: {change.verdict}"
    return text + (f" ({change.message})" if change.message else "")


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Monitor until the input ends."""
    from tlmpc.base.errors import UsageError, error
    from tlmpc.fleet.monitor import Monitor
    from tlmpc.importers.logs import CsvLines, parse_columns, parse_transform
    from tlmpc.io.report import OUTCOME_EXIT, Reporter
    from tlmpc.verify.trace_input import mission_document

    report = Reporter.for_args(args, out, err)
    name = "<stdin>" if args.log == "-" else args.log
    try:
        monitor = Monitor(mission_document(Path(name), args.mission), convention=args.boundary)
    except UsageError as exc:  # what the mission asks that the monitor cannot: the mission's
        raise UsageError(
            [
                d if d.file else dataclasses.replace(d, file=str(args.mission))
                for d in exc.diagnostics
            ]
        ) from None
    columns = parse_columns(args.columns) if args.columns else None
    transform = parse_transform(args.transform) if args.transform else None
    csv = CsvLines(name, columns)
    if args.log == "-":
        stream: TextIO = sys.stdin
    else:
        try:
            stream = open(args.log, encoding="utf-8-sig")  # noqa: SIM115 - closed below
        except OSError as exc:
            raise UsageError(
                error("M050", f"cannot read {name}: {exc.strerror or exc}", file=name)
            ) from None
    try:
        for number, raw in enumerate(_lines(stream, args.follow, args.idle), start=1):
            text = raw.strip()
            pose: tuple[float, float, float] | None
            if text.startswith("{"):
                pose = _json_pose(text, name, number)
            else:
                pose = csv.parse(raw, number)
            if pose is None:
                continue
            t, x, y = pose
            if transform is not None:
                c, s = math.cos(transform[2]), math.sin(transform[2])
                x, y = c * x - s * y + transform[0], s * x + c * y + transform[1]
            try:
                monitor.add(t, x, y, line=number)
            except UsageError as exc:
                raise UsageError(
                    [d if d.file else dataclasses.replace(d, file=name) for d in exc.diagnostics]
                ) from None
            for change in monitor.changes():
                report.stream(_line(change, args.jsonl))
    finally:
        if stream is not sys.stdin:
            stream.close()
    if monitor.samples == 0:
        raise UsageError(error("V002", "no poses were read", file=name))
    for change in monitor.finish():
        report.stream(_line(change, args.jsonl))
    text = "" if args.jsonl else f"{name}: {monitor.outcome} after {monitor.samples:,} poses\n"
    result = {"verdict": monitor.outcome, "poses": monitor.samples, "verdicts": monitor.verdicts}
    return report.finish(OUTCOME_EXIT[monitor.outcome], result, text)


def _json_pose(text: str, name: str, number: int) -> tuple[float, float, float]:
    from tlmpc.base.errors import UsageError, error

    try:
        record = json.loads(text)
        values = (record["t"], record["x"], record["y"])
        # numbers only: float() would also take "5", true and "1_0"
        if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
            raise TypeError
        return float(values[0]), float(values[1]), float(values[2])
    except (ValueError, KeyError, TypeError):
        raise UsageError(
            error(
                "M053",
                'a JSON line must be an object {"t": ..., "x": ..., "y": ...} of numbers',
                file=name,
                line=number,
            )
        ) from None
