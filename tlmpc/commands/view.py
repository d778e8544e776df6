"""``tlmpc view OUT`` / ``tlmpc view --log LOG --mission M``: one self-contained HTML page.

Exit 0 when the page is written (whatever the verdict it shows), 2 when the input cannot be
read.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TextIO

from tlmpc.commands.log_flags import LOG_FORMATS, add_log_flags, log_options

NAME = "view"
HELP = "write an interactive HTML view of a compile output or of a verified log"
DESCRIPTION = """\
Write one self-contained HTML page (no network needed to open it): the map, the regions, the
triangulation on demand, the trajectory animated over time (play, pause, scrub), the regions and
triangle under the pointer, and the counterexample of a failed verification highlighted.
Either OUT, a directory written by `tlmpc compile`, or --log LOG with --mission MISSION,
verified here: LOG is any log `tlmpc verify` reads (a trace.json, a CSV of t,x,y rows, a ROS 1
.bag, a ROS 2 bag directory or an .mcap file), with the same --topic, --columns, --transform
and --frame."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("out", type=Path, nargs="?", help="a `tlmpc compile` output directory")
    parser.add_argument("--log", type=Path, help=f"a robot log: {LOG_FORMATS}")
    parser.add_argument("--mission", type=Path, help="the mission file the log is checked against")
    parser.add_argument(
        "-o",
        "--output",
        type=Path,
        help="the HTML file to write (default: OUT/view.html, or LOG with .html)",
    )
    parser.add_argument("--json", action="store_true", help="one JSON document: the page written")
    add_log_flags(parser)


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Build the scene, render it and write the page atomically."""
    from tlmpc.base.errors import EXIT_OK, UsageError, error
    from tlmpc.io.artifacts import ARTIFACT_SCHEMAS
    from tlmpc.io.outdir import replace_file
    from tlmpc.io.outputs import plain_name, refuse_input_as_output
    from tlmpc.io.report import Reporter
    from tlmpc.view import render_html, scene_from_log, scene_from_output

    if (args.out is None) == (args.log is None) or (args.log is not None) != (
        args.mission is not None
    ):
        raise UsageError(
            error(
                "U092",
                "give either OUT, or --log LOG with --mission MISSION",
                hint="`tlmpc view out` or `tlmpc view --log run.csv --mission mission.yaml`",
            )
        )
    if args.log is not None:
        target = args.output or _page_beside(args.log)
        inputs = [args.log, args.mission]
    else:
        target = args.output or args.out / "view.html"
        inputs = [args.out / name for name in ARTIFACT_SCHEMAS]
    refuse_input_as_output(target, inputs)
    if args.log is not None:
        scene = scene_from_log(args.log, args.mission, log_options(args))
    else:
        scene = scene_from_output(args.out)
    page = render_html(scene)
    if not target.parent.is_dir():
        raise UsageError(
            error(
                "U093",
                f"cannot write {target}: {target.parent} is not a directory",
                hint="create the directory first, or choose another file with -o",
                file=str(target),
            )
        )
    replace_file(target, page.encode("utf-8"))
    report = Reporter.for_args(args, out, err)
    return report.finish(EXIT_OK, {"written": [str(target)]}, f"wrote {plain_name(str(target))}\n")


def _page_beside(log: Path) -> Path:
    """LOG.html next to a log file; for a bag directory, DIR.html beside the directory."""
    if log.is_dir():
        return log.parent / f"{log.name}.html"
    return log.with_suffix(".html")
