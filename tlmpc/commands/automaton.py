"""``tlmpc automaton 'LTL'``: translate a formula on its own (like Spot's ``ltl2tgba``)."""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence
from typing import TextIO

from tlmpc.io.artifacts import json_text

NAME = "automaton"
HELP = "translate an LTL formula to a generalized Büchi automaton (HOA, DOT or JSON)"
DESCRIPTION = """\
Translate FORMULA (LTL without X) into a transition-based generalized Büchi automaton and
print it.  --ba degeneralizes to a state-based Büchi automaton.  An invalid formula exits 1
with its diagnostics."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("formula", help="the LTL formula, e.g. 'G F a & G F b'")
    parser.add_argument(
        "--format", choices=("hoa", "dot", "json"), default="hoa", help="output format"
    )
    parser.add_argument("--ba", action="store_true", help="degeneralize to a state-based BA")
    parser.add_argument(
        "--stats", action="store_true", help="print states, edges, acceptance sets and time"
    )
    parser.add_argument(
        "--json",
        action="store_true",
        help="one JSON document: the statistics with --stats, else the automaton (tlmpc JSON)",
    )


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Translate and print."""
    from tlmpc.automata import automaton_to_json, degeneralize, to_dot, to_hoa, translate
    from tlmpc.base.errors import EXIT_OK
    from tlmpc.io.report import Reporter
    from tlmpc.ltl import parse_ltl
    from tlmpc.ltl.bounds import refuse_bounds

    formula = parse_ltl(args.formula, file="<formula>")
    refuse_bounds(formula, file="<formula>", purpose="the automaton translation")
    started = time.perf_counter()
    automaton = translate(formula)
    if args.ba:
        automaton = degeneralize(automaton)
    seconds = time.perf_counter() - started
    report = Reporter.for_args(args, out, err)
    if args.stats:
        stats = {
            "formula": automaton.formula,
            "states": automaton.num_states,
            "edges": len(automaton.edges),
            "acceptance_sets": automaton.num_acc,
            "state_based": automaton.state_based,
            "seconds": round(seconds, 6),
        }
        text = (
            f"states: {stats['states']}\nedges: {stats['edges']}\n"
            f"acceptance sets: {stats['acceptance_sets']}\n"
            f"time: {seconds * 1000:.2f} ms\n"
        )
        return report.finish(EXIT_OK, {"stats": stats}, text)
    document = automaton_to_json(automaton)
    if args.format == "hoa":
        text = to_hoa(automaton)
        if not args.json:
            _refuse_unprintable_hoa(automaton.aps)
    elif args.format == "dot":
        text = to_dot(automaton)
    else:
        text = json_text(document)
    return report.finish(EXIT_OK, {"automaton": document}, text)


def _refuse_unprintable_hoa(aps: Sequence[str]) -> None:
    """Refuse (U079) HOA whose AP names hold characters tlmpc never prints as they are.

    Everything printed has control and direction characters escaped (``\\u202e``), but an
    HOA string has no such escapes: a reader would take the escape for other characters,
    so the automaton would name other APs (two may even meet).  Newlines and tabs are
    printed as they are, and HOA strings hold them."""
    from tlmpc.base.errors import UsageError, error, printable

    odd = [name for name in aps if printable(name) != name]
    if odd:
        shown = ", ".join(f'"{printable(name)}"' for name in odd)
        raise UsageError(
            error(
                "U079",
                f"the atomic propositions {shown} hold control or direction characters, "
                "which tlmpc prints escaped and an HOA string cannot hold escaped",
                hint="--format json (or --json) keeps these names exactly",
                file="<formula>",
            )
        )
