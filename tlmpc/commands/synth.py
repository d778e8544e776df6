"""``tlmpc synth SPEC``: GR(1) synthesis on gr1c, slugs and TLSF specifications.

Exit 0 when the specification is realizable, 1 when it is not (with a minimal core and a
counterstrategy), 2 when the specification cannot be read.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

if TYPE_CHECKING:
    from tlmpc.synth.core import Core
    from tlmpc.synth.counter import CounterStrategy
    from tlmpc.synth.spec import GameSpec

NAME = "synth"
HELP = "GR(1) synthesis of a gr1c (.spc), slugs (.slugsin, .structuredslugs) or TLSF specification"
DESCRIPTION = """\
Decide whether SPEC is realizable: whether the system has a strategy that meets its guarantees
whatever the environment does within its assumptions (docs/synthesis.md gives each format's
reading).  Prints `realizable` (exit 0) or `unrealizable` (exit 1) followed, for the latter, by
a minimal set of guarantees that is already unrealizable (file:line:col each) and a
counterstrategy: how the environment's inputs defeat every system strategy.  -o writes the
winning strategy (a Mealy machine) as JSON (schemas/strategy.schema.json) or DOT."""

#: how many counterstrategy nodes the text shows (all of them are in --json)
SHOWN_NODES = 40


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument(
        "spec", type=Path, help="the specification (.spc, .slugsin, .structuredslugs or .tlsf)"
    )
    parser.add_argument(
        "--input-format",
        choices=("gr1c", "slugsin", "structuredslugs", "tlsf"),
        help="the specification's format (default: by its suffix)",
    )
    parser.add_argument(
        "-o", "--output", type=Path, metavar="FILE", help="write the winning strategy to FILE"
    )
    parser.add_argument(
        "--format", choices=("json", "dot"), default="json", help="strategy format for -o"
    )
    parser.add_argument(
        "--symbolic",
        action="store_true",
        help="with -o (JSON): write the strategy as decision diagrams, one per output bit, "
        "instead of listing the machine's nodes (for strategies too large to list)",
    )
    parser.add_argument(
        "--all-init",
        action="store_true",
        help="every initial state allowed by both initial conditions must be winning "
        "(gr1c -n ALL_INIT, slugs --sysInitRoboticsSemantics)",
    )
    parser.add_argument(
        "--one-side-init",
        action="store_true",
        help="gr1c's -n ONE_SIDE_INIT reading of the initial conditions (.spc only)",
    )
    parser.add_argument(
        "--no-explain",
        action="store_true",
        help="for an unrealizable specification, skip the core and the counterstrategy",
    )
    parser.add_argument("--json", action="store_true", help="print the answer as JSON")


def _fail_flag(args: argparse.Namespace, fmt: str, flag: str) -> None:
    from tlmpc.base.errors import UsageError, error

    raise UsageError(
        error(
            "Q063",
            f"{flag} does not apply to {fmt} specifications",
            hint="--all-init reads gr1c and slugs files, --one-side-init gr1c files; TLSF "
            "fixes its own initial reading (Mealy)",
            file=str(args.spec),
        )
    )


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Read, solve, explain, write."""
    from tlmpc.base.errors import EXIT_NEGATIVE, EXIT_OK, UsageError, error
    from tlmpc.io.report import Reporter
    from tlmpc.synth.readers import format_of, read_spec
    from tlmpc.synth.solver import Game, solve

    reporter = Reporter.for_args(args, out, err)
    fmt = args.input_format or format_of(str(args.spec))
    if args.all_init and fmt not in ("gr1c", "slugsin", "structuredslugs"):
        _fail_flag(args, fmt or "these", "--all-init")
    if args.one_side_init and fmt != "gr1c":
        _fail_flag(args, fmt or "these", "--one-side-init")
    if args.symbolic and (args.output is None or args.format != "json"):
        raise UsageError(
            error(
                "Q063",
                "--symbolic applies to a JSON strategy written with -o",
                hint="add -o FILE.json (and leave --format at json)",
            )
        )
    if args.all_init and args.one_side_init:
        raise UsageError(
            error(
                "Q063",
                "--all-init and --one-side-init are two readings of the same conditions",
                hint="choose one",
            )
        )
    if args.output is not None and not args.output.parent.is_dir():
        raise UsageError(
            error(
                "Q061",
                f"cannot write {args.output}: {args.output.parent} is not a directory",
                hint="create the directory first",
                file=str(args.output),
            )
        )
    mode = "all_init" if args.all_init else "one_side" if args.one_side_init else None
    spec = read_spec(str(args.spec), fmt=fmt, init_mode=mode)  # type: ignore[arg-type]
    game = Game.build(spec)
    solution = solve(game)
    result: dict[str, Any] = {
        "realizable": solution.realizable,
        "format": spec.source_format,
        "initial_quantification": spec.init_mode,
        "variables": {"inputs": len(spec.owned("env")), "outputs": len(spec.owned("sys"))},
        "parts": len(spec.parts),
    }
    if solution.realizable:
        if args.output is not None:
            from tlmpc.io.artifacts import json_text as document_text
            from tlmpc.io.outdir import replace_file
            from tlmpc.synth.strategy import extract, to_dot, to_json

            if args.symbolic:
                from tlmpc.synth.symbolic_strategy import (
                    reachable_size,
                    symbolic_document,
                    symbolic_strategy,
                )

                size = reachable_size(solution)
                symbolic = symbolic_strategy(solution)
                document = symbolic_document(symbolic, size)
                replace_file(args.output, document_text(document).encode("utf-8"))
                result["strategy"] = {
                    "file": str(args.output),
                    "diagram nodes": len(symbolic.diagram.nodes),
                    "reachable nodes": size.nodes,
                    "reachable transitions": size.transitions,
                }
                reporter.note(
                    f"wrote {args.output} ({len(symbolic.diagram.nodes)} diagram nodes; "
                    f"{size.nodes} reachable nodes, {size.transitions} transitions)"
                )
                return reporter.finish(EXIT_OK, result, "realizable\n")
            machine = extract(solution)
            text = to_dot(machine) if args.format == "dot" else document_text(to_json(machine))
            replace_file(args.output, text.encode("utf-8"))
            result["strategy"] = {
                "file": str(args.output),
                "nodes": len(machine.states),
                "transitions": len(machine.transitions),
            }
            reporter.note(
                f"wrote {args.output} ({len(machine.states)} nodes, "
                f"{len(machine.transitions)} transitions)"
            )
        return reporter.finish(EXIT_OK, result, "realizable\n")
    if args.output is not None:
        reporter.note(f"no strategy to write: {args.spec} is unrealizable")
    text = "unrealizable\n"
    if not args.no_explain:
        from tlmpc.synth.core import minimal_core
        from tlmpc.synth.counter import extract_counterstrategy

        core = minimal_core(spec, game.enc)
        counter: CounterStrategy | None = None
        try:
            counter = extract_counterstrategy(solve(core.game(game.enc)))
        except UsageError as exc:
            if exc.diagnostics[0].code != "Q062":
                raise
            # too large to show: the answer and the core still stand (a note, not a failure)
            reporter.diagnose(dataclasses.replace(d, severity="note") for d in exc.diagnostics)
        result["core"] = [
            {
                "file": p.location.file,
                "line": p.location.line,
                "col": p.location.col,
                "part": p.label,
                "text": p.text,
            }
            for p in core.parts
        ]
        if counter is not None:
            result["counterstrategy"] = _counter_json(counter)
        text += _explain(spec, core, counter)
    return reporter.finish(EXIT_NEGATIVE, result, text)


def _values(values: dict[str, Any]) -> str:
    words = []
    for name, value in values.items():
        if value is True:
            words.append(name)
        elif value is False:
            words.append(f"!{name}")
        else:
            words.append(f"{name}={value}")
    return " ".join(words) or "(none)"


def _shorten(text: str, width: int = 90) -> str:
    return text if len(text) <= width else text[: width - 3] + "..."


def _explain(spec: GameSpec, core: Core, counter: CounterStrategy | None) -> str:
    inputs = [v.name for v in spec.owned("env")]
    outputs = [v.name for v in spec.owned("sys")]
    count = len(core.parts)
    lines = [
        f"core: {'this guarantee is' if count == 1 else f'these {count} guarantees are'} "
        "unrealizable (under every assumption):"
    ]
    for part in core.parts:
        lines.append(f"  {part.location}: {part.label}: {_shorten(part.text)}")
    if counter is None:
        return "\n".join(lines) + "\n"
    lines.append(f"counterstrategy ({len(counter.states)} nodes): the environment plays")
    if counter.initial_inputs is not None:
        lines.append(f"  first inputs: {_values(counter.initial_inputs)}")
        if not counter.initial:
            lines.append("  and no first outputs satisfy the system's initial condition")
    for node, state in enumerate(counter.states):
        if node == SHOWN_NODES:
            lines.append(f"  ... {len(counter.states) - node} more nodes (see --json)")
            break
        here = _values({k: state[k] for k in inputs + outputs})
        goal = counter.memory[node][0]
        answers = counter.answers[node]
        then = (
            "the system has no allowed answer"
            if not answers
            else "then " + ", ".join(f"n{t}" for t in answers)
        )
        lines.append(
            f"  n{node} [{here}] (starving goal {goal}): inputs "
            f"{_values(counter.moves[node])}; {then}"
        )
    if counter.initial:
        lines.append("  starting in " + ", ".join(f"n{i}" for i in counter.initial))
    return "\n".join(lines) + "\n"


def _counter_json(counter: CounterStrategy) -> dict[str, Any]:
    return {
        "initial_inputs": counter.initial_inputs,
        "initial": list(counter.initial),
        "nodes": [
            {
                "id": i,
                "state": state,
                "starving_goal": counter.memory[i][0],
                "inputs": counter.moves[i],
                "answers": list(counter.answers[i]),
            }
            for i, state in enumerate(counter.states)
        ],
    }
