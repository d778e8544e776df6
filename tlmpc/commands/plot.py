"""``tlmpc plot OUT``: draw a compile output's plan, optionally with a recorded log over it."""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TextIO

from tlmpc.base.errors import UsageError, error

NAME = "plot"
HELP = "draw plan.svg (or plan.png) from a compile output, optionally with a log over the map"
DESCRIPTION = """\
Re-draw the picture of a compile output directory OUT from its artifacts: the map, holes,
regions, mesh, plan, trajectory (coloured by distance travelled) and start.  plan.svg is
written directly; --format png draws plan.png with matplotlib.

With --log FILE (a CSV of t,x,y rows or a trace.json) the log is drawn over the map and its
violations are marked: from --verdict VERDICT.json when given, otherwise by running the
verifier on the log against the mission's task.  The pictures are then log.svg / log.png.
--zoom x0,y0,x1,y1 draws only that window of the map (narrow doors, dense meshes)."""

_INPUTS = {
    "mission.json": "tlmpc.mission/",
    "abstraction.json": "tlmpc.abstraction/",
    "witness.json": "tlmpc.witness/",
    "trace.json": "tlmpc.trace/",
}


def parse_zoom(text: str) -> tuple[float, float, float, float]:
    """``x0,y0,x1,y1`` -> a window with x0 < x1 and y0 < y1 (argparse type)."""
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
    parser.add_argument(
        "--log", type=Path, help="a recorded trajectory to draw: CSV t,x,y or trace.json"
    )
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


def _log_samples(path: Path) -> tuple[list[list[float]], dict[str, Any] | None]:
    """The log's ``[t, x, y]`` rows, and its document when it is a trace.json."""
    from tlmpc.io.artifacts import read_json

    if path.suffix.lower() == ".csv":
        from tlmpc.verify.trace_input import read_csv

        samples, _ = read_csv(path)
        return samples.tolist(), None
    document = read_json(path, "tlmpc.trace/")
    points = document.get("points")
    if not isinstance(points, list) or not points:
        raise UsageError(error("V002", "the trace has no samples", file=str(path)))
    return points, document


def _verify_log(
    samples: list[list[float]],
    document: Mapping[str, Any] | None,
    mission: Mapping[str, Any],
    path: Path,
) -> dict[str, Any]:
    """Run the verifier on the log (against the mission of the compile output for a CSV)."""
    from tlmpc.verify import verdict_to_json, verify_document

    if document is None:
        options = mission.get("options") or {}
        document = {
            "format": "tlmpc.trace/1",
            "ltl": mission["formula"],
            "regions": mission["regions"],
            "workspace": mission["workspace"],
            "boundary": options.get("boundary"),
            "max_speed": (mission.get("robot") or {}).get("max_speed"),
            "points": samples,
            "loop_start": None,
        }
    return verdict_to_json(verify_document(dict(document), file=str(path)))


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Read the artifacts of ``args.out`` and write the picture(s) next to them."""
    from tlmpc.base.errors import EXIT_OK
    from tlmpc.io.artifacts import read_artifacts, read_json
    from tlmpc.io.outdir import replace_file
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
        verdict = read_json(args.verdict, "tlmpc.verdict/")
    if args.log is not None:
        log, document = _log_samples(args.log)
        if verdict is None:
            verdict = _verify_log(log, document, artifacts["mission.json"], args.log)
    stem = "log" if log is not None else "plan"
    written = []
    if args.format in ("svg", "both"):
        from tlmpc.render.plot import render_svg

        svg = render_svg(artifacts, zoom=args.zoom, log=log, verdict=verdict)
        replace_file(directory / f"{stem}.svg", svg)
        written.append(f"{stem}.svg")
    if args.format in ("png", "both"):
        from tlmpc.render.plot import render_png

        png = render_png(artifacts, zoom=args.zoom, log=log, verdict=verdict)
        replace_file(directory / f"{stem}.png", png)
        written.append(f"{stem}.png")
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
