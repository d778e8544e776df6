"""``tlmpc plot OUT``: draw a compile output's plan, optionally with a recorded log over it."""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from tlmpc.base.errors import UsageError, error
from tlmpc.commands.log_flags import LOG_FORMATS, add_log_flags, log_options

if TYPE_CHECKING:
    from tlmpc.verify import TraceInput

NAME = "plot"
HELP = "draw plan.svg (or plan.png) from a compile output, optionally with a log over the map"
DESCRIPTION = """\
Re-draw the picture of a compile output directory OUT from its artifacts: the map, holes,
regions, mesh, plan, trajectory (coloured by distance travelled) and start.  plan.svg is
written directly; --format png draws plan.png with matplotlib.

With --log FILE (a trace.json, a CSV of t,x,y rows, a ROS 1 .bag, a ROS 2 bag directory or
an .mcap file: every format `tlmpc verify` reads, with its --topic, --columns, --transform and
--frame) the log is drawn over the map and its violations are marked: from --verdict
VERDICT.json when given, otherwise by running the verifier on the log against the mission of
the compile output.  The pictures are then log.svg / log.png.
--zoom x0,y0,x1,y1 draws only that window of the map (narrow doors, dense meshes)."""

_INPUTS = {
    "mission.json": "tlmpc.mission/",
    "abstraction.json": "tlmpc.abstraction/",
    "witness.json": "tlmpc.witness/",
    "trace.json": "tlmpc.trace/",
    "counterstrategy.json": "tlmpc.counterstrategy/",
}


def parse_zoom(text: str) -> tuple[float, float, float, float]:
    """``x0,y0,x1,y1`` -> a window with x0 < x1 and y0 < y1 and a finite width and height
    (argparse type)."""
    import math

    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected four numbers x0,y0,x1,y1, got {text!r}"
        ) from None
    if len(values) != 4 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"expected four numbers x0,y0,x1,y1, got {text!r}")
    x0, y0, x1, y1 = values
    if not (x0 < x1 and y0 < y1):
        raise argparse.ArgumentTypeError(f"empty window {text!r}: need x0 < x1 and y0 < y1")
    # the picture's scale divides by the window's size: it must be a number too
    if not (math.isfinite(x1 - x0) and math.isfinite(y1 - y0)):
        raise argparse.ArgumentTypeError(
            f"window {text!r} too large: its width and height must be finite numbers"
        )
    return x0, y0, x1, y1


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("out", type=Path, help="a directory written by `tlmpc compile`")
    parser.add_argument(
        "--format",
        choices=("svg", "png", "both"),
        default="svg",
        help="which picture to write (default: svg; png needs matplotlib and is slower)",
    )
    parser.add_argument("--log", type=Path, help=f"a recorded trajectory to draw: {LOG_FORMATS}")
    parser.add_argument(
        "--verdict",
        type=Path,
        help="a verdict.json whose violations to mark (default: verify the log)",
    )
    parser.add_argument(
        "--zoom", type=parse_zoom, metavar="x0,y0,x1,y1", help="draw only this window of the map"
    )
    parser.add_argument(
        "--json", action="store_true", help="one JSON document: the files written and the verdict"
    )
    add_log_flags(parser)


def _read_log(
    args: argparse.Namespace, mission: Mapping[str, Any]
) -> tuple[list[list[float]], TraceInput]:
    """The log's ``[t, x, y]`` samples, read as ``tlmpc verify`` reads it, against the
    compile output's mission."""
    from tlmpc.mission.io import mission_from_json
    from tlmpc.verify import read_trace

    trace = read_trace(args.log, mission_from_json(mission), None, log_options(args))
    samples = [
        [t, x, y] for t, (x, y) in zip(trace.times.tolist(), trace.points.tolist(), strict=True)
    ]
    return samples, trace


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Read the artifacts of ``args.out`` and write the picture(s) next to them."""
    from tlmpc.base.errors import EXIT_OK
    from tlmpc.io.artifacts import read_artifact, read_artifacts
    from tlmpc.io.outdir import replace_files
    from tlmpc.io.report import Reporter

    directory: Path = args.out
    if not (directory / "mission.json").is_file():
        raise UsageError(
            error(
                "U020",
                f"{directory} has no mission.json",
                hint="pass a directory written by `tlmpc compile MISSION -o DIR`",
                file=str(directory),
            )
        )
    artifacts: dict[str, Any] = read_artifacts(directory, tuple(_INPUTS))
    log: list[list[float]] | None = None
    verdict: dict[str, Any] | None = None
    if args.verdict is not None:
        # checked against the verdict schema, as the verdict.json of an output is: the
        # scene trusts every field it draws
        verdict = read_artifact(args.verdict, "verdict")
    if args.log is not None:
        from tlmpc.verify import verdict_to_json, verify_trace

        log, trace = _read_log(args, artifacts["mission.json"])
        if verdict is None:
            verdict = verdict_to_json(verify_trace(trace))
    stem = "log" if log is not None else "plan"
    pictures: dict[str, bytes] = {}
    if args.format in ("svg", "both"):
        from tlmpc.render.plot import render_svg

        pictures[f"{stem}.svg"] = render_svg(artifacts, zoom=args.zoom, log=log, verdict=verdict)
    if args.format in ("png", "both"):
        from tlmpc.render.plot import render_png

        pictures[f"{stem}.png"] = render_png(artifacts, zoom=args.zoom, log=log, verdict=verdict)
    # both pictures or neither: a refused or failed one leaves the other as it was
    replace_files({directory / name: picture for name, picture in pictures.items()})
    written = list(pictures)
    tail = ""
    if verdict is not None:
        marks = sum(
            1
            for key in ("counterexample", "workspace_violation")
            if isinstance(verdict.get(key), dict) and verdict[key].get("position") is not None
        )
        status = verdict.get("verdict") or ("satisfied" if verdict.get("satisfied") else "violated")
        tail = f" ({status}; {marks} violation(s) marked)"
    reporter = Reporter.for_args(args, out, err)
    if not args.json:
        reporter.note(f"wrote {', '.join(written)} to {directory}{tail}")
    return reporter.finish(
        EXIT_OK, {"written": [str(directory / name) for name in written], "verdict": verdict}
    )
