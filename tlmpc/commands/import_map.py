"""``tlmpc import-map MAP.yaml -o MISSION.yaml``: a mission from an occupancy-grid map."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TextIO

NAME = "import-map"
HELP = "write a mission from a ROS map_server / nav2 map (and keepout / speed masks)"
DESCRIPTION = """\
Turn an occupancy-grid map (map.yaml + image, map_server conventions) into a mission with
explicit polygons: free cells become the workspace (unknown space is not free), eroded by
--radius (configuration space of a disc robot), simplified within --tolerance; a keepout mask
becomes regions keepout_K (group keepout), a speed mask regions speed_V_K (groups speed_V).
The task defaults to `avoid keepout` when a keepout mask is given.  See docs/robot-data.md."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("map", type=Path, help="a map_server map YAML file")
    parser.add_argument("-o", "--output", type=Path, help="mission file (default: stdout)")
    parser.add_argument("--keepout", type=Path, help="a nav2 keepout mask YAML")
    parser.add_argument("--speed", type=Path, help="a nav2 speed mask YAML")
    parser.add_argument(
        "--radius", type=float, default=0.0, help="robot radius: erode free space by it"
    )
    parser.add_argument(
        "--tolerance", type=float, help="simplification tolerance (default: one cell)"
    )
    parser.add_argument(
        "--min-area",
        type=float,
        help="drop obstacle specks and free pieces smaller than this (default: 4 cells)",
    )
    parser.add_argument(
        "--start",
        type=float,
        nargs=2,
        metavar=("X", "Y"),
        help="robot start (default: the free point farthest from obstacles and keepout)",
    )
    parser.add_argument(
        "--task", action="append", help="a task phrase (repeatable; default: avoid keepout)"
    )
    parser.add_argument("--ltl", help="a raw LTL task")
    parser.add_argument("--max-speed", type=float, default=1.0, help="robot max speed")
    parser.add_argument("--name", help="mission name (default: the map's file name)")
    parser.add_argument(
        "--region",
        action="append",
        nargs=5,
        metavar=("NAME", "XMIN", "YMIN", "XMAX", "YMAX"),
        help="add a rectangular region, clipped to the workspace boundary (repeatable)",
    )


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Import the map and write the mission."""
    from tlmpc.base.errors import EXIT_OK
    from tlmpc.importers.maps import ImportSettings, import_map
    from tlmpc.importers.mission import mission_document, mission_yaml
    from tlmpc.io.outdir import replace_file
    from tlmpc.io.report import Reporter

    settings = ImportSettings(
        radius=args.radius,
        tolerance=args.tolerance,
        min_area=args.min_area,
        start=tuple(args.start) if args.start else None,
    )
    imported = import_map(args.map, settings, keepout=args.keepout, speed=args.speed)
    document = mission_document(
        imported,
        name=args.name or args.map.stem,
        start=tuple(args.start) if args.start else None,
        task=args.task,
        ltl=args.ltl,
        max_speed=args.max_speed,
        rects=_rects(args.region or []),
    )
    if args.output is not None:
        from tlmpc.io.outputs import refuse_input_as_output

        refuse_input_as_output(args.output, [Path(name) for name in imported.inputs])
    text = mission_yaml(document)
    ratio = imported.workspace_area / imported.free_cells_area if imported.free_cells_area else 0
    summary = (
        f"workspace {imported.workspace_area:.6g} (free cells {imported.free_cells_area:.6g}, "
        f"{100 * ratio:.2f}%), {len(imported.boundary)} boundary vertices, "
        f"{len(imported.holes)} holes, {len(imported.components)} further free components, "
        f"{len(imported.regions)} mask regions"
    )
    reporter = Reporter.for_args(args, out, err)
    if args.output is None:
        return reporter.finish(EXIT_OK, text=text)
    replace_file(args.output, text.encode("utf-8"))
    reporter.note(f"wrote {args.output}: {summary}")
    return reporter.finish(EXIT_OK)


def _rects(values: list[list[str]]) -> dict[str, tuple[float, float, float, float]]:
    from tlmpc.base.errors import UsageError, error

    rects: dict[str, tuple[float, float, float, float]] = {}
    for name, *numbers in values:
        try:
            x0, y0, x1, y1 = (float(v) for v in numbers)
        except ValueError:
            raise UsageError(
                error("M017", f"--region {name}: the bounds must be numbers, got {numbers}")
            ) from None
        rects[name] = (x0, y0, x1, y1)
    return rects
