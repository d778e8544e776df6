"""``tlmpc verify TRACE``: re-check a trajectory against its task in continuous time.

Exit 0 when the task holds, 1 when it is violated, 4 when a log that may go on is
inconclusive, 2 when the trace cannot be read.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from tlmpc.commands.log_flags import add_log_flags, log_options

if TYPE_CHECKING:
    from tlmpc.verify.model import Verdict

NAME = "verify"
HELP = "check a trajectory (trace.json, or a CSV/ROS bag log with --mission) against its task"
DESCRIPTION = """\
Check TRACE against its task under the continuous-time semantics of LTL (docs/semantics.md).
TRACE is a trace.json written by `tlmpc compile` (self-contained), or a robot log whose
regions and task come from --mission: a CSV (header naming t/time, x, y, extra columns ignored,
--columns to choose; comments and , ; tab or space separators), a ROS 1 .bag, a ROS 2 bag
directory (sqlite3 or MCAP) or a .mcap file (pose topic chosen with --topic); see
docs/robot-data.md.

A log that simply ends gets a three-valued verdict: satisfied (no continuation can break the
task), violated (none can repair it) or inconclusive; --assume-stay reads it as staying at its
last point forever, --loop-from T as repeating its part from time T on.  Prints the verdict,
each conjunct's own verdict and progress, every violation (when and where), the robustness
and whether the verdict is certified for the real robot between samples."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("trace", type=Path, help="trace.json, a CSV log or a ROS bag")
    parser.add_argument("--mission", type=Path, help="mission file (needed for CSV traces)")
    parser.add_argument(
        "--boundary",
        choices=("right", "closed"),
        help="labelling convention at region boundaries (default: the trace's, else right)",
    )
    ending = parser.add_mutually_exclusive_group()
    ending.add_argument(
        "--assume-stay",
        action="store_true",
        help="read the log as staying at its last point forever (two-valued verdict)",
    )
    ending.add_argument(
        "--loop-from",
        type=float,
        metavar="T",
        help="the part of the log from time T to its end repeats forever (two-valued verdict)",
    )
    parser.add_argument("--json", action="store_true", help="print the verdict as JSON")
    add_log_flags(parser)


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Verify and report."""
    from tlmpc.io.report import OUTCOME_EXIT, Reporter
    from tlmpc.verify import declare_ending, read_trace, verdict_to_json, verify_trace

    path: Path = args.trace
    trace = read_trace(path, args.mission, args.boundary, log_options(args))
    trace = declare_ending(trace, assume_stay=args.assume_stay, loop_from=args.loop_from)
    verdict = verify_trace(trace)
    report = Reporter.for_args(args, out, err)
    text = _text(path, verdict)
    return report.finish(OUTCOME_EXIT[verdict.outcome], verdict_to_json(verdict), text)


def _text(path: Path, verdict: Verdict) -> str:
    lines: list[str] = []
    status = {"satisfied": "satisfied", "violated": "VIOLATED", "inconclusive": "inconclusive"}
    ending = {
        "open": "the log ends here (three-valued verdict)",
        "stay": "the robot stays at its last point forever",
        "loop": "the loop repeats forever",
    }[verdict.ending]
    lines.append(f"{path}: {status[verdict.outcome]}: {verdict.formula}")
    lines.append(f"  boundary convention: {verdict.convention}; {ending}; {verdict.pieces} pieces")
    if len(verdict.conjuncts) > 1 or verdict.ending == "open":
        for report in verdict.conjuncts:
            lines.append(f"  {report.conjunct}: {report.outcome}: {report.progress}")
    for violation in verdict.violations:
        lines.append(f"  violation: {violation.message}")
    lines.append(f"  robustness: {verdict.robustness:.6g}")
    certificate = verdict.certificate
    word = "certified" if certificate.certified else "not certified"
    lines.append(f"  {word}: {certificate.reason}")
    return "".join(line + "\n" for line in lines)
