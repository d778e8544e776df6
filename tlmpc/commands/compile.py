"""``tlmpc compile MISSION -o OUT``: run the pipeline and write every artifact atomically."""

from __future__ import annotations

import argparse
import gc
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TextIO

NAME = "compile"
HELP = "compile a mission into a verified plan, controllers and trajectory"
DESCRIPTION = """\
Lower MISSION through every stage (load, abstraction, automaton, plan, control, simulate,
verify, plot) and write the artifacts into OUT: mission.json, abstraction.json,
automaton.json, automaton.hoa, witness.json, controllers.json, trace.json, verdict.json,
summary.json and the picture plan.svg (plus plan.png with --png).  Output is atomic: a
failed run leaves OUT untouched."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    from tlmpc.pipeline.stages import stage_names

    parser.add_argument("mission", type=Path, help="mission file (YAML)")
    parser.add_argument(
        "-o", "--out", type=Path, default=Path("out"), help="output directory (default: out)"
    )
    parser.add_argument(
        "--until",
        choices=stage_names(),
        metavar="STAGE",
        help="stop after STAGE (one of: %(choices)s)",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="write into OUT even if it is a non-empty directory that tlmpc did not create",
    )
    parser.add_argument(
        "--png",
        action="store_true",
        help="also draw plan.png with matplotlib (slower; plan.svg is always written)",
    )
    parser.add_argument(
        "--json", action="store_true", help="print summary.json on stdout (as the result)"
    )
    parser.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        help="no progress lines (neither per stage nor while a long stage runs)",
    )


def _format_sizes(sizes: dict[str, object]) -> str:
    return ", ".join(f"{key} {value}" for key, value in sizes.items() if key != "formula")


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Compile ``args.mission`` into ``args.out``."""
    from tlmpc.io.outdir import output_lock

    with output_lock(args.out):
        return _run_locked(args, out, err)


def _run_locked(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from tlmpc.base.errors import EXIT_OK
    from tlmpc.io.outdir import (
        KNOWN_ARTIFACTS,
        check_destination,
        clean_stale,
        commit,
        refuse_deleting_foreign,
        refuse_overwriting,
        staging_directory,
        write_artifacts,
    )
    from tlmpc.io.report import Reporter
    from tlmpc.pipeline.stages import StageReport, collector_paused, compile_mission

    reporter = Reporter.for_args(args, out, err)
    destination: Path = args.out
    if args.png:  # before any stage runs: a missing extra is known at once
        from tlmpc.base.extras import require

        require("matplotlib.backends.backend_agg", "drawing a PNG figure (--png)")
    check_destination(destination, force=args.force)
    refuse_overwriting(destination, sorted(KNOWN_ARTIFACTS), args.mission)
    refuse_deleting_foreign(destination, force=args.force)
    for note in clean_stale(destination):
        reporter.note(f"tlmpc: note: {note}")

    def progress(index: int, total: int, report: StageReport) -> None:
        if not args.quiet:
            sizes = _format_sizes(dict(report.sizes))
            reporter.note(
                f"[{index}/{total}] {report.name:<11} {report.seconds:8.3f} s"
                + (f"  {sizes}" if sizes else "")
            )

    # One pause for compiling and writing: re-enabling in between would trigger a full
    # collection over everything the compilation still holds.
    from tlmpc.reactive.unrealizable import UnrealizableError

    with collector_paused():
        try:
            result = compile_mission(
                args.mission,
                until=args.until,
                progress=None if args.quiet else progress,  # --quiet: no heartbeat either
                figures=("svg", "png") if args.png else ("svg",),
            )
        except UnrealizableError as failure:
            # an unrealizable reactive mission: OUT shows how the environment wins
            # (tlmpc plot / view draw counterstrategy.json); the answer is still exit 1
            with staging_directory(destination) as staging:
                write_artifacts(staging, dict(failure.artifacts))
                commit(staging, destination, force=args.force)
            if not args.json and not args.quiet:
                reporter.note(
                    f"wrote {len(failure.artifacts)} artifacts to {destination} "
                    "(the environment's winning play: tlmpc plot / tlmpc view)"
                )
            raise
        reporter.diagnose(result.warnings)
        with staging_directory(destination) as staging:
            artifacts = dict(result.artifacts)
            summary = result.summary()
            artifacts["summary.json"] = summary
            write_artifacts(staging, artifacts)
            commit(staging, destination, force=args.force)
        # The process ends soon: hand everything allocated so far to the permanent
        # generation, so that re-enabling the collector does not walk it all once more
        # (a tenth of Example 8's compile; seconds on a million triangles).
        gc.freeze()

    if not args.json and not args.quiet:
        verdict = summary.get("verdict")
        tail = ""
        if verdict is not None:
            tail = f"; trace verifies (robustness {verdict['robustness']:.4g})"
        bounds = summary.get("bounds")
        if bounds:  # each time bound with its slack on the trajectory
            held = ", ".join(_held(b) for b in bounds)
            tail += f"; time bounds held: {held}"
        reporter.note(f"wrote {len(artifacts)} artifacts to {destination}{tail}")
    return reporter.finish(EXIT_OK, summary)


def _held(bound: Mapping[str, Any]) -> str:
    """A bound and its slack as printed: ``F[0,45] dock by 13.34 s``, ``... by any amount``
    (``inf``); a bound without a slack (it occurs both ways, under ``<->``: moving it helps
    one side and hurts the other) is printed alone."""
    slack = bound["slack"]
    if isinstance(slack, int | float):
        return f"{bound['bound']} by {slack:.4g} s"
    if slack == "inf":
        return f"{bound['bound']} by any amount"
    return str(bound["bound"])
