"""``tlmpc export-plan OUT --format ...``: a compiled plan for a navigation stack."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TextIO

NAME = "export-plan"
HELP = "export a compiled plan as waypoints (YAML, CSV), a nav_msgs/Path MCAP file or GeoJSON"
DESCRIPTION = """\
Export the plan of a compiled mission (OUT holds trace.json and mission.json, written by
`tlmpc compile`) for a navigation stack: waypoints as YAML or CSV (with the loop start, so a
patrol can repeat its cycle), a nav_msgs/Path message in an MCAP file, or GeoJSON of the map,
regions, trajectory and waypoints.  Coordinates are the mission's (the map frame for imported
maps).  See docs/robot-data.md."""

FORMATS = ("waypoints-yaml", "waypoints-csv", "path-mcap", "geojson")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("out", type=Path, help="a directory written by `tlmpc compile`")
    parser.add_argument("--format", choices=FORMATS, default="waypoints-yaml")
    parser.add_argument(
        "-o", "--output", type=Path, help="write to this file (default: stdout; required for MCAP)"
    )
    parser.add_argument(
        "--spacing",
        type=float,
        default=0.0,
        help="keep waypoints at least this far apart (default 0: every trajectory sample)",
    )
    parser.add_argument("--frame-id", default="map", help="frame of the poses (default: map)")
    parser.add_argument("--topic", default="/plan", help="path-mcap: the topic (default: /plan)")
    parser.add_argument(
        "--georeference",
        metavar="LAT,LON[,YAW]",
        type=_georeference,
        help="geojson: the map origin's WGS 84 latitude and longitude and the angle from east "
        "to the map's x axis (degrees, counter-clockwise): coordinates become longitude, "
        "latitude (RFC 7946) instead of the map's metres",
    )


def _georeference(text: str) -> object:
    from tlmpc.exports.georeference import parse_georeference

    return parse_georeference(text)


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Read the plan and write the chosen format."""
    import math
    import shlex

    from tlmpc.base.errors import EXIT_OK, UsageError, error
    from tlmpc.exports.formats import geojson, path_mcap, waypoints_csv, waypoints_yaml
    from tlmpc.exports.plan import read_plan, waypoints
    from tlmpc.io.outdir import replace_file
    from tlmpc.io.outputs import has_unsafe_chars, plain_name, refuse_input_as_output

    if not math.isfinite(args.spacing) or args.spacing < 0:
        raise UsageError(
            error(
                "M082",
                f"--spacing must be a non-negative number, got {args.spacing:g}",
                hint="the least distance between kept waypoints, in map units (0: every "
                "trajectory sample)",
                file=f"--spacing {args.spacing:g}",
            )
        )
    for flag, value in (("--frame-id", args.frame_id), ("--topic", args.topic)):
        if not value or has_unsafe_chars(value):
            raise UsageError(
                error(
                    "M084",
                    f"{flag} {plain_name(value)!r} is empty or holds control, newline or "
                    "direction characters",
                    hint=f"give a plain {flag} such as "
                    + ("map" if flag == "--frame-id" else "/plan"),
                    file=f"{flag} {shlex.quote(plain_name(value))}",
                )
            )
    if args.output is not None:
        refuse_input_as_output(
            args.output, [args.out / n for n in ("trace.json", "mission.json", "controllers.json")]
        )
    if args.output is not None and not args.output.parent.is_dir():
        raise UsageError(
            error(
                "M083",
                f"cannot write {args.output}: {args.output.parent} is not a directory",
                hint="create the directory first",
                file=str(args.output),
            )
        )
    if args.georeference is not None and args.format != "geojson":
        raise UsageError(
            error(
                "M086",
                f"--georeference applies to geojson, not to {args.format}",
                hint="the other formats are in the map frame, as a navigation stack expects",
                file="--georeference",
            )
        )
    if args.format == "path-mcap" and args.output is None:
        raise UsageError(
            error("M083", "path-mcap is binary: give -o FILE.mcap", hint="-o plan.mcap")
        )
    plan = read_plan(args.out)
    points, loop = waypoints(plan, args.spacing)
    data: bytes
    if args.format == "waypoints-yaml":
        data = waypoints_yaml(plan, points, loop, args.frame_id).encode("utf-8")
    elif args.format == "waypoints-csv":
        data = waypoints_csv(plan, points, loop).encode("utf-8")
    elif args.format == "geojson":
        try:
            data = geojson(plan, points, loop, args.georeference).encode("utf-8")
        except ValueError:  # a non-finite number, which JSON cannot hold
            raise UsageError(
                error(
                    "M081",
                    f"the plan in {args.out} holds a number that is not finite",
                    hint="this output was edited or damaged; compile the mission again",
                    file=str(args.out),
                )
            ) from None
    else:
        data = path_mcap(plan, points, args.topic, args.frame_id, source=args.out / "trace.json")
    from tlmpc.io.report import Reporter

    reporter = Reporter.for_args(args, out, err)
    if args.output is None:
        return reporter.finish(EXIT_OK, text=data.decode("utf-8"))
    replace_file(args.output, data)
    reporter.note(f"wrote {args.output} ({len(points)} waypoints)")
    return reporter.finish(EXIT_OK)
