"""``tlmpc verify TRACE``: re-check a trajectory against its task in continuous time.

Exit 0 when the task holds, 1 when it is violated, 2 when the trace cannot be read.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TextIO

NAME = "verify"
HELP = "check a trajectory (trace.json, or a CSV/ROS bag log with --mission) against its task"
DESCRIPTION = """\
Check TRACE against its task under the continuous-time semantics of LTL (docs/semantics.md).
TRACE is a trace.json written by `tlmpc compile` (self-contained), or a robot log whose
regions and task come from --mission: a CSV (header naming t/time, x, y, extra columns ignored,
--columns to choose; comments and , ; tab or space separators), a ROS 1 .bag, a ROS 2 bag
directory (sqlite3 or MCAP) or a .mcap file (pose topic chosen with --topic); see
docs/robot-data.md.  Prints the
verdict, the robustness and, for a violation, what fails, when and where."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("trace", type=Path, help="trace.json, a CSV log or a ROS bag")
    parser.add_argument("--mission", type=Path, help="mission file (needed for CSV traces)")
    parser.add_argument(
        "--boundary",
        choices=("right", "closed"),
        help="labelling convention at region boundaries (default: the trace's, else right)",
    )
    parser.add_argument("--json", action="store_true", help="print the verdict as JSON")
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


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Verify and report."""
    from tlmpc.artifacts import read_json
    from tlmpc.importers.logs import is_log, parse_columns, parse_transform
    from tlmpc.verify import from_csv, from_document, verdict_to_json, verify_trace

    path: Path = args.trace
    if is_log(path):
        trace = from_csv(
            path,
            args.mission,
            args.boundary,
            topic=args.topic,
            columns=parse_columns(args.columns) if args.columns else None,
            transform=parse_transform(args.transform) if args.transform else None,
        )
    else:
        document = read_json(path)
        trace = from_document(document, file=str(path), convention=args.boundary)
    verdict = verify_trace(trace)
    document = verdict_to_json(verdict)
    if args.json:
        out.write(json.dumps(document, indent=2, sort_keys=True) + "\n")
    else:
        status = "satisfied" if verdict.satisfied else "VIOLATED"
        out.write(f"{path}: {status}: {verdict.formula}\n")
        out.write(f"  boundary convention: {verdict.convention}; {verdict.pieces} pieces\n")
        out.write(f"  robustness: {verdict.robustness:.6g}")
        if verdict.certificate_bound is not None:
            if verdict.certified:
                out.write(
                    f" > max_speed * max gap = {verdict.certificate_bound:.4g}: the "
                    "verdict is robust (certified)\n"
                )
            else:
                out.write(
                    f" (certificate needs > max_speed * max gap = "
                    f"{verdict.certificate_bound:.4g}; not certified)\n"
                )
        else:
            out.write("\n")
        for example in (verdict.workspace_violation, verdict.counterexample):
            if example is not None:
                out.write(f"  counterexample: {example.message}\n")
    return 0 if verdict.satisfied else 1
