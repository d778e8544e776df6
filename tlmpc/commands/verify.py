"""``tlmpc verify TRACE...``: re-check trajectories against their task in continuous time.

One trace: exit 0 when the task holds, 1 when it is violated, 4 when a log that may go on is
inconclusive, 2 when the trace cannot be read.  Many logs (or a folder, or a batch flag): a
line per log as it finishes, a summary, and one exit code for the batch (see
:func:`tlmpc.fleet.batch.batch_exit`).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from tlmpc.commands.log_flags import add_log_flags, log_options

if TYPE_CHECKING:
    from tlmpc.verify.model import Verdict

NAME = "verify"
HELP = (
    "check trajectories (trace.json, or CSV/ROS bag logs and folders with --mission) against a task"
)
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
and whether the verdict is certified for the real robot between samples.

Several logs, or folders of logs, are a batch: verified in parallel (--jobs, --dask), one
line per log as it finishes, a summary table, --results as JSON lines or Parquet, a content
cache so unchanged logs are not verified again, and --report for a fleet page; see
docs/verify.md ("Many logs")."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument(
        "trace",
        type=Path,
        nargs="+",
        help="trace.json, a CSV log or a ROS bag; several logs or folders of logs: a batch",
    )
    parser.add_argument(
        "--mission",
        type=Path,
        help="mission file (needed for logs), or a tlmpc.fleet-missions/1 mapping file",
    )
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
    batch = parser.add_argument_group("many logs")
    batch.add_argument(
        "--jobs",
        type=int,
        metavar="N",
        help="verify N logs at once in local processes (default: all cores)",
    )
    batch.add_argument(
        "--dask",
        metavar="ADDRESS",
        help="verify on the Dask cluster whose scheduler is at ADDRESS (the [fleet] extra)",
    )
    batch.add_argument(
        "--results",
        type=Path,
        metavar="FILE",
        help="write a record per log: JSON lines, or Parquet for FILE.parquet (needs pyarrow)",
    )
    batch.add_argument(
        "--report",
        type=Path,
        metavar="FILE",
        help="write the fleet report (one HTML page; each log's view in FILE's .views folder)",
    )
    batch.add_argument(
        "--group",
        metavar="REGEX",
        help="report: groups `robot` and `day` found in each log's path (default: the first "
        "folder under the batch's common folder is the robot, a YYYY-MM-DD in the path the day)",
    )
    batch.add_argument(
        "--cache",
        type=Path,
        metavar="DIR",
        help="the verification cache (default: $TLMPC_CACHE_DIR or ~/.cache/tlmpc/verify)",
    )
    batch.add_argument(
        "--no-cache", action="store_true", help="verify every log again, store nothing"
    )


BATCH_FLAGS = ("jobs", "dask", "results", "report", "group", "cache")


def _is_batch(args: argparse.Namespace) -> bool:
    paths: list[Path] = args.trace
    if len(paths) > 1 or args.no_cache or any(getattr(args, f) is not None for f in BATCH_FLAGS):
        return True
    only = paths[0]
    if only.is_dir() and not (only / "metadata.yaml").is_file():
        return True
    if args.mission is not None:
        from tlmpc.fleet.batch import read_mapping

        return read_mapping(args.mission) is not None
    return False


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Verify and report."""
    if _is_batch(args):
        from tlmpc.fleet.command import run_batch

        return run_batch(args, out, err)
    return _run_one(args, args.trace[0], out, err)


def _run_one(args: argparse.Namespace, path: Path, out: TextIO, err: TextIO) -> int:
    from tlmpc.importers.logs import is_log
    from tlmpc.io.report import OUTCOME_EXIT, Reporter
    from tlmpc.verify import declare_ending, read_trace, verdict_to_json, verify_trace

    report = Reporter.for_args(args, out, err)
    if is_log(path) and _too_large_for_memory(path, args.topic):
        verdict = _streamed(args, path)
        report.note(
            f"{path}: streamed ({verdict.stats['samples']:,} samples, "
            f"{verdict.stats['kept_samples']:,} kept); robustness and certificate are the kept "
            "samples'"
        )
        text = _text(path, verdict)
        return report.finish(OUTCOME_EXIT[verdict.outcome], verdict_to_json(verdict), text)
    trace = read_trace(path, args.mission, args.boundary, log_options(args))
    trace = declare_ending(trace, assume_stay=args.assume_stay, loop_from=args.loop_from)
    verdict = verify_trace(trace)
    text = _text(path, verdict)
    return report.finish(OUTCOME_EXIT[verdict.outcome], verdict_to_json(verdict), text)


def _too_large_for_memory(path: Path, topic: str | None) -> bool:
    """A CSV log past the whole reader's size, or a bag of many pose messages: streamed."""
    from tlmpc.base.errors import TlmpcError
    from tlmpc.importers.logs import BAG_STREAM_FROM, CSV_SUFFIXES, bag_pose_count
    from tlmpc.verify.trace_input import is_large_csv

    if path.suffix.lower() in CSV_SUFFIXES and not path.is_dir():
        return path.is_file() and is_large_csv(path)
    try:
        return bag_pose_count(path, topic) > BAG_STREAM_FROM
    except TlmpcError:
        return False  # the whole reader gives the same diagnostic


def _streamed(args: argparse.Namespace, path: Path) -> Verdict:
    """A CSV log too large to hold whole or a long bag, verified in constant memory
    (docs/verify.md)."""
    from tlmpc.fleet.stream import verify_log
    from tlmpc.importers.logs import parse_columns, parse_transform
    from tlmpc.verify.trace_input import mission_document

    streamed = verify_log(
        path,
        mission_document(path, args.mission),
        convention=args.boundary,
        topic=args.topic,
        columns=parse_columns(args.columns) if args.columns else None,
        transform=parse_transform(args.transform) if args.transform else None,
        frame=args.frame,
        assume_stay=args.assume_stay,
        loop_from=args.loop_from,
    )
    return streamed.verdict


def _text(path: Path, verdict: Verdict) -> str:
    lines: list[str] = []
    status = {"satisfied": "satisfied", "violated": "VIOLATED", "inconclusive": "inconclusive"}
    ending = {
        "open": "the log ends here (three-valued verdict)",
        "stay": "the robot stays at its last point forever",
        "loop": "the loop repeats forever",
    }[verdict.ending]
    word = status[verdict.outcome]
    if verdict.reactive is not None and verdict.reactive.blame == "environment":
        word += " (vacuously: the environment broke an assumption)"
    lines.append(f"{path}: {word}: {verdict.formula}")
    lines.append(f"  boundary convention: {verdict.convention}; {ending}; {verdict.pieces} pieces")
    timed = any(r.time_robustness is not None for r in verdict.conjuncts)
    if len(verdict.conjuncts) > 1 or verdict.ending == "open" or timed:
        for report in verdict.conjuncts:
            lines.append(f"  {report.conjunct}: {report.outcome}: {report.progress}")
    if verdict.reactive is not None:
        from tlmpc.verify.blame import blame_lines

        lines.extend(blame_lines(verdict.reactive, float(verdict.stats["start_time"])))
    for violation in verdict.violations:
        lines.append(f"  violation: {violation.message}")
    lines.append(f"  robustness: {verdict.robustness:.6g}")
    slack = verdict.time_robustness
    if slack is not None and math.isinf(slack):
        decided = "holds" if slack > 0 else "fails"
        lines.append(f"  time robustness: {slack:g} (the task {decided} at any time bound)")
    elif slack is not None:
        lines.append(
            f"  time robustness: {slack:.6g} s "
            "(how much tighter the time bounds could be; < 0: how much looser they must be)"
        )
    certificate = verdict.certificate
    word = "certified" if certificate.certified else "not certified"
    lines.append(f"  {word}: {certificate.reason}")
    return "".join(line + "\n" for line in lines)
