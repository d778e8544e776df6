"""``tlmpc import-map MAP.yaml -o MISSION.yaml``: a mission from an occupancy-grid map."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TextIO

NAME = "import-map"
HELP = "write a mission from a ROS map_server / nav2 map (and keepout / speed masks)"
DESCRIPTION = """\
Turn an occupancy-grid map (map.yaml + image, map_server conventions) into a mission with
explicit polygons: free cells become the workspace (unknown space is not free), simplified
within --tolerance; with --radius eroded by the radius plus that tolerance (the configuration
space of a disc robot, kept however the simplification moves the boundary); a keepout mask
becomes regions keepout_K (group keepout), a speed mask regions speed_V_K (groups speed_V).
The task defaults to `avoid keepout` when a keepout mask is given.  See docs/robot-data.md."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("map", type=Path, help="a map_server map YAML file")
    parser.add_argument("-o", "--output", type=Path, help="mission file (default: stdout)")
    parser.add_argument("--keepout", type=Path, help="a nav2 keepout mask YAML")
    parser.add_argument("--speed", type=Path, help="a nav2 speed mask YAML")
    parser.add_argument(
        "--radius",
        type=float,
        default=0.0,
        help="robot radius: erode free space by it, plus the tolerance (so the simplified "
        "workspace keeps the radius from obstacles)",
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
        "-q", "--quiet", action="store_true", help="no progress lines while a long import runs"
    )
    parser.add_argument(
        "--region",
        action="append",
        nargs=5,
        metavar=("NAME", "XMIN", "YMIN", "XMAX", "YMAX"),
        help="add a rectangular region, clipped to the workspace boundary (repeatable, each "
        "with its own name)",
    )


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Import the map and write the mission."""
    from tlmpc.base.errors import EXIT_OK
    from tlmpc.importers.maps import ImportSettings, import_map
    from tlmpc.importers.mission import mission_document, mission_yaml, unfinished
    from tlmpc.io.outdir import replace_file
    from tlmpc.io.report import Reporter

    settings = ImportSettings(
        radius=args.radius,
        tolerance=args.tolerance,
        min_area=args.min_area,
        start=tuple(args.start) if args.start else None,
        # a robot with a body can hit an obstacle of a few cells: none is filled as a speck
        keep_obstacles=args.radius > 0,
    )
    import contextlib
    import sys

    from tlmpc.base.progress import heartbeat

    rects, flags = _rects(args.region or [])
    with contextlib.nullcontext() if args.quiet else heartbeat("import-map", sys.stderr):
        imported = import_map(args.map, settings, keepout=args.keepout, speed=args.speed)
    document = mission_document(
        imported,
        name=args.name or args.map.stem,
        start=tuple(args.start) if args.start else None,
        task=args.task,
        ltl=args.ltl,
        max_speed=args.max_speed,
        rects=rects,
        flags=flags,
    )
    if args.output is not None:
        from tlmpc.io.outputs import refuse_input_as_output

        refuse_input_as_output(args.output, [Path(name) for name in imported.inputs])
    _check_flags(args, document.get("groups") or {})
    text = mission_yaml(document)
    missing = unfinished(document)
    if not missing:
        _check_task(text, args)
    ratio = imported.workspace_area / imported.free_cells_area if imported.free_cells_area else 0
    summary = (
        f"workspace {imported.workspace_area:.6g} (free cells {imported.free_cells_area:.6g}, "
        f"{100 * ratio:.2f}%), {len(imported.boundary)} boundary vertices, "
        f"{len(imported.holes)} holes, {len(imported.components)} further free components, "
        f"{len(imported.regions)} mask regions"
        + (f", free space eroded by {imported.erosion:g}" if imported.erosion else "")
    )
    reporter = Reporter.for_args(args, out, err)
    if args.output is None:
        return reporter.finish(EXIT_OK, text=text)
    replace_file(args.output, text.encode("utf-8"))
    reporter.note(f"wrote {args.output}: {summary}")
    if missing:
        reporter.note(
            f"note: the mission has no {' and no '.join(missing)} yet: add them to "
            f"{args.output} (see its first lines), then run `tlmpc check {args.output}`"
        )
    return reporter.finish(EXIT_OK)


def _check_flags(args: argparse.Namespace, groups: dict[str, list[str]]) -> None:
    """Read every --task phrase and the --ltl formula on their own, located at the flag
    (`--ltl 'G(':1:3`): a syntax error is the command's error (exit 1, nothing written) even
    when the mission has no regions yet; unknown names are checked with the whole mission."""
    from tlmpc.base.errors import Diagnostic, InvalidInputError
    from tlmpc.tasks.compiler import compile_phrase

    problems: list[Diagnostic] = []
    for phrase in args.task or []:
        try:
            compile_phrase(phrase, groups=groups, file=f"--task {phrase!r}")
        except InvalidInputError as exc:
            problems.extend(exc.diagnostics)
    if args.ltl is not None:
        from tlmpc.ltl.parser import parse_ltl

        try:
            parse_ltl(args.ltl, file=f"--ltl {args.ltl!r}")
        except InvalidInputError as exc:
            problems.extend(exc.diagnostics)
    if problems:
        raise InvalidInputError(problems)


def _check_task(text: str, args: argparse.Namespace) -> None:
    """Load the mission about to be written; its errors (an unknown region in a --task, an
    --ltl that does not parse, a --max-speed too small to cross the map) are the command's,
    located at the flag (exit 1, nothing written)."""
    import dataclasses

    from tlmpc.base.errors import InvalidInputError
    from tlmpc.mission.load import load_mission_text

    name = str(args.output) if args.output is not None else "<stdout>"
    try:
        load_mission_text(text, name)
    except InvalidInputError as exc:
        lines = text.splitlines()
        located = []
        for problem in exc.diagnostics:
            if problem.severity != "error":
                continue
            if problem.path == "$.robot.max_speed":  # S010: the speed comes from the flag
                located.append(
                    dataclasses.replace(
                        problem, file=f"--max-speed {args.max_speed:g}", line=None, col=None
                    )
                )
                continue
            row = lines[problem.line - 1] if problem.line and problem.line <= len(lines) else ""
            flag = _flag_at(row, problem.col, args)
            if flag is not None:
                where, start = flag
                col = (problem.col - start) if problem.col and start >= 0 else None
                problem = dataclasses.replace(problem, file=where, line=1, col=col)
            located.append(problem)
        raise InvalidInputError(located or list(exc.diagnostics)) from None


def _rects(
    values: list[list[str]],
) -> tuple[dict[str, tuple[float, float, float, float]], dict[str, str]]:
    """The ``--region`` rectangles by name, and each one's flag as given (where its
    diagnostics are located).  Refused (M017, at the flag): bounds that are not numbers, and
    a name an earlier ``--region`` gave, whose rectangle would otherwise be silently lost."""
    import shlex

    from tlmpc.importers.mission import region_error

    rects: dict[str, tuple[float, float, float, float]] = {}
    flags: dict[str, str] = {}
    for words in values:
        name, *numbers = words
        flag = shlex.join(["--region", *words])
        if name in flags:
            raise region_error(
                flag,
                f"the region {name!r} is already given by `{flags[name]}`",
                "give each --region its own name (a group of the mission can then name several)",
            )
        try:
            x0, y0, x1, y1 = (float(v) for v in numbers)
        except ValueError:
            raise region_error(
                flag,
                f"the bounds must be numbers, got {' '.join(numbers)}",
                "--region NAME XMIN YMIN XMAX YMAX, in map units",
            ) from None
        rects[name] = (x0, y0, x1, y1)
        flags[name] = flag
    return rects, flags


def _flag_at(row: str, col: int | None, args: argparse.Namespace) -> tuple[str, int] | None:
    """The --task or --ltl flag whose text sits at column ``col`` of the mission's ``row``,
    and where that text starts in the row."""
    spans = [(f"--task {p!r}", p) for p in args.task or []]
    if args.ltl:
        spans.append((f"--ltl {args.ltl!r}", args.ltl))
    for flag, text in spans:
        start = row.find(text)
        while start >= 0:
            if col is None or start < col <= start + len(text):
                return flag, start
            start = row.find(text, start + 1)
    return None
