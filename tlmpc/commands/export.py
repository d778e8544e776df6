"""``tlmpc export OUT --format promela|smv|dot``: D and the negated task for model checkers."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TextIO

NAME = "export"
HELP = "write the transition system and negated task for SPIN (promela), NuSMV (smv) or DOT"
DESCRIPTION = """\
Export the transition system D of a compiled mission (OUT holds abstraction.json and
mission.json, written by `tlmpc compile --until abstraction` or a full compile) together with
the negated task, the paper's model-checker route: a counterexample to !task is a plan."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("out", type=Path, help="a directory written by `tlmpc compile`")
    parser.add_argument("--format", choices=("promela", "smv", "dot"), default="promela")
    parser.add_argument("-o", "--output", type=Path, help="write to this file (default: stdout)")


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Read the artifacts and print (or write) the model."""
    from tlmpc.abstraction import abstraction_from_json
    from tlmpc.artifacts import read_json
    from tlmpc.errors import UsageError, error
    from tlmpc.ltl import parse_ltl
    from tlmpc.planning.export import to_dot_graph, to_promela, to_smv

    directory: Path = args.out
    for name in ("abstraction.json", "mission.json"):
        if not (directory / name).is_file():
            raise UsageError(
                error(
                    "U020",
                    f"{directory} has no {name}",
                    hint="run `tlmpc compile MISSION -o DIR --until abstraction` first",
                    file=str(directory),
                )
            )
    abstraction = abstraction_from_json(
        read_json(directory / "abstraction.json", "tlmpc.abstraction/")
    )
    mission = read_json(directory / "mission.json", "tlmpc.mission/")
    formula = parse_ltl(mission["formula"])
    title = str(mission.get("name", "mission"))
    if args.format == "promela":
        text = to_promela(abstraction, formula, title)
    elif args.format == "smv":
        text = to_smv(abstraction, formula, title)
    else:
        text = to_dot_graph(abstraction, title)
    if args.output is not None:
        args.output.write_text(text, encoding="utf-8")
        err.write(f"wrote {args.output}\n")
    else:
        out.write(text)
    return 0
