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
    parser.add_argument(
        "--bounce",
        action="store_true",
        help="promela/smv: the paper's plain D, which may leave a triangle through the edge it "
        "entered by (default: tlmpc's no-bounce rule, so the checker plans what tlmpc can realise)",
    )


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Read the artifacts and print (or write) the model."""
    from tlmpc.abstraction import abstraction_from_json
    from tlmpc.base.errors import EXIT_OK, UsageError, error
    from tlmpc.io.artifacts import read_artifacts
    from tlmpc.io.outdir import replace_file
    from tlmpc.io.outputs import refuse_input_as_output
    from tlmpc.ltl import parse_ltl
    from tlmpc.planning.export import to_dot_graph, to_promela, to_smv

    directory: Path = args.out
    if args.output is not None:
        refuse_input_as_output(
            args.output, [directory / "abstraction.json", directory / "mission.json"]
        )
    if args.output is not None and not args.output.parent.is_dir():
        raise UsageError(
            error(
                "U021",
                f"cannot write {args.output}: {args.output.parent} is not a directory",
                hint="create the directory first, or leave out -o to print the model",
                file=str(args.output),
            )
        )
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
    documents = read_artifacts(directory, ("mission.json", "abstraction.json"))
    abstraction = abstraction_from_json(documents["abstraction.json"])
    mission = documents["mission.json"]
    formula = parse_ltl(mission["formula"])
    title = str(mission.get("name", "mission"))
    reactive = mission.get("reactive") or {}
    if args.format in ("promela", "smv") and reactive:
        signals = sorted({*reactive.get("sensors", {}), *reactive.get("actions", [])})
        raise UsageError(
            error(
                "U078",
                f"{directory} is a reactive mission's output: its task reads sensors and "
                f"actions ({', '.join(signals)}), which a {args.format} model of the "
                "transition system has no variables for",
                hint="--format dot draws the transition system alone; the robot's strategy "
                f"is {directory / 'strategy.json'}",
                file=str(directory / "mission.json"),
            )
        )
    if args.format in ("promela", "smv"):
        from tlmpc.ltl.bounds import refuse_bounds

        # SPIN's and NuSMV's LTL have no time bounds (L045 rather than a dropped bound)
        refuse_bounds(formula, file="<formula>", purpose=f"the {args.format} export")
    if args.format == "promela":
        text = to_promela(abstraction, formula, title, bounce=args.bounce)
    elif args.format == "smv":
        text = to_smv(abstraction, formula, title, bounce=args.bounce)
    else:
        text = to_dot_graph(abstraction, title)
    from tlmpc.io.report import Reporter

    reporter = Reporter.for_args(args, out, err)
    if args.output is None:
        return reporter.finish(EXIT_OK, text=text)
    replace_file(args.output, text.encode("utf-8"))
    reporter.note(f"wrote {args.output}")
    return reporter.finish(EXIT_OK)
