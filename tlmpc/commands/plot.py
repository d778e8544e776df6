"""``tlmpc plot OUT``: re-draw ``plan.png``/``plan.svg`` from a compile output's artifacts."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any, TextIO

from tlmpc.errors import UsageError, error

NAME = "plot"
HELP = "re-draw plan.png and plan.svg from the artifacts in a compile output directory"

_INPUTS = {
    "mission.json": "tlmpc.mission/",
    "abstraction.json": "tlmpc.abstraction/",
    "witness.json": "tlmpc.witness/",
    "trace.json": "tlmpc.trace/",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("out", type=Path, help="a directory written by `tlmpc compile`")
    parser.add_argument(
        "--format",
        choices=("png", "svg", "both"),
        default="both",
        help="which figure files to write (default: both)",
    )


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Read the artifacts of ``args.out`` and write the figures next to them."""
    from tlmpc.artifacts import read_output
    from tlmpc.output import replace_file
    from tlmpc.plot import render_plan

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
    artifacts: dict[str, Any] = read_output(directory, tuple(_INPUTS))
    png, svg = render_plan(artifacts)
    written = []
    if args.format in ("png", "both"):
        replace_file(directory / "plan.png", png)
        written.append("plan.png")
    if args.format in ("svg", "both"):
        replace_file(directory / "plan.svg", svg)
        written.append("plan.svg")
    err.write(f"wrote {', '.join(written)} to {directory}\n")
    return 0
