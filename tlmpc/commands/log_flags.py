"""The flags of every command that reads a robot log (verify, plot --log, view --log)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from tlmpc.verify.trace_input import LogOptions

#: What a log may be, for the commands' help.
LOG_FORMATS = (
    "a trace.json, a CSV of t,x,y rows, a ROS 1 .bag, a ROS 2 bag directory (sqlite3 or MCAP) "
    "or a .mcap file"
)


def add_log_flags(parser: argparse.ArgumentParser) -> None:
    """Register --topic, --columns, --transform and --frame (see docs/robot-data.md)."""
    parser.add_argument(
        "--topic", help="bags: the pose topic (needed when several topics carry poses)"
    )
    parser.add_argument(
        "--columns",
        metavar="TIME,X,Y",
        help="CSV logs: the time and position columns, by name or 1-based number",
    )
    parser.add_argument(
        "--transform",
        metavar="X,Y,YAW",
        help="logs: map the log's frame into the mission's (p = R(YAW) p_log + (X, Y))",
    )
    parser.add_argument(
        "--frame",
        metavar="FRAME",
        help="bags: express the poses in FRAME (e.g. map) through the bag's /tf and /tf_static "
        "(default: the poses' own frame)",
    )


def log_options(args: argparse.Namespace) -> LogOptions:
    """The :class:`LogOptions` of parsed flags (checked: U-/M- diagnostics on bad values)."""
    from tlmpc.importers.logs import parse_columns, parse_transform
    from tlmpc.verify.trace_input import LogOptions

    return LogOptions(
        topic=args.topic,
        columns=parse_columns(args.columns) if args.columns else None,
        transform=parse_transform(args.transform) if args.transform else None,
        frame=args.frame,
    )
