"""``tlmpc simulate OUT``: run the compiled controllers in closed loop under a disturbance.

Exit 0 when the simulated trajectory satisfies the task, 1 when it violates it (or the robot
had to stop: no plan from where it was pushed), 4 when the run ended before a verdict was
possible (no complete lap), 2 on bad flags or an unreadable output folder.
"""

from __future__ import annotations

import argparse
import contextlib
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from tlmpc.base.errors import UsageError, error
from tlmpc.io.artifacts import dumps

if TYPE_CHECKING:
    from collections.abc import Mapping

    from tlmpc.runtime import ClosedLoopRun
    from tlmpc.verify.model import Verdict

NAME = "simulate"
HELP = "simulate the compiled controllers in closed loop under a bounded disturbance"
DESCRIPTION = """\
Run the runtime executor on OUT (a folder written by `tlmpc compile`) in closed loop: the
robot's velocity is the executor's command plus a disturbance w with |w| <= --disturbance
(default: the mission's robot.disturbance), random (seeded piecewise-constant noise) or
adversarial (the worst push at every instant).  The executor tracks the plan step, re-enters
the plan or re-plans when the robot is pushed into another triangle.  The run lasts --cycles
laps of the plan's cycle (or dwell times in a final stay; default 2) or --duration seconds;
the trajectory (of the reference point, for a unicycle) is verified by the independent
verifier and written with -o.  For a reactive mission (OUT has strategy.json) the strategy
runs against --sensors random, adversarial or a CSV file of timed readings for --events
events.  See docs/cli.md and docs/control.md."""


def _positive(text: str, what: str, code: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value <= 0.0:
        raise UsageError(
            error(code, f"{what} must be a positive number, not {text!r}", hint=f"give {what}")
        )
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("out", type=Path, help="output folder of `tlmpc compile`")
    parser.add_argument(
        "--disturbance",
        metavar="D",
        help="bound on the disturbance's norm (default: the mission's robot.disturbance)",
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="random seed, a whole number >= 0 (default 0)"
    )
    parser.add_argument(
        "--model-disturbance",
        choices=("random", "adversarial"),
        default="random",
        help="random: seeded piecewise-constant noise; adversarial: the worst push (default "
        "random)",
    )
    length = parser.add_mutually_exclusive_group()
    length.add_argument("--cycles", metavar="K", help="laps of the cycle to run (default 2)")
    length.add_argument("--duration", metavar="T", help="seconds to run")
    parser.add_argument("--dt", metavar="S", help="sample period (default: from the mesh)")
    parser.add_argument(
        "--heading", type=float, default=0.0, help="unicycle: initial heading in radians"
    )
    parser.add_argument(
        "--sensors",
        metavar="SOURCE",
        help="reactive missions: random, adversarial, or a CSV FILE of timed readings "
        "(default random)",
    )
    parser.add_argument(
        "--events", metavar="N", help="reactive missions: events to run (default 200)"
    )
    parser.add_argument("-o", "--output", type=Path, help="write the trace.json here")
    parser.add_argument("--json", action="store_true", help="print the report as JSON")


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Simulate, verify and report."""
    from tlmpc.base.errors import EXIT_NEGATIVE
    from tlmpc.commands.simulate_reactive import check_seed, is_reactive_output
    from tlmpc.io.report import OUTCOME_EXIT, Reporter
    from tlmpc.runtime import Executor, make_disturbance, run_closed_loop

    if args.sensors is not None or args.events is not None or is_reactive_output(args.out):
        from tlmpc.commands.simulate_reactive import run_reactive_command

        return run_reactive_command(args, out, err)
    if args.disturbance is not None:
        bound = float("nan")
        with contextlib.suppress(ValueError):
            bound = float(args.disturbance)
        if not math.isfinite(bound) or bound < 0.0:
            raise UsageError(
                error(
                    "U080",
                    f"--disturbance must be a number >= 0, not {args.disturbance!r}",
                    hint="give the bound on the disturbance's norm, in the unit of max_speed",
                )
            )
    cycles = None
    duration = None
    if args.duration is not None:
        duration = _positive(args.duration, "--duration", "U081")
    else:
        cycles_value = _positive(args.cycles or "2", "--cycles", "U081")
        if cycles_value != int(cycles_value):
            raise UsageError(error("U081", f"--cycles must be a whole number, not {args.cycles!r}"))
        cycles = int(cycles_value)
    dt = _positive(args.dt, "--dt", "U082") if args.dt is not None else None
    check_seed(args.seed, "disturbance")
    if args.output is not None:
        from tlmpc.io.outputs import refuse_input_as_output
        from tlmpc.runtime.executor import EXECUTOR_ARTIFACTS

        refuse_input_as_output(args.output, [args.out / name for name in EXECUTOR_ARTIFACTS])
    executor = Executor.from_output(args.out)
    declared = executor.mission.robot.disturbance
    if args.disturbance is None:
        bound = declared
    hold = 10.0 * dt if dt is not None else math.nan
    if dt is None:
        from tlmpc.runtime.closed_loop import default_dt

        hold = 10.0 * default_dt(executor.plan, executor.mission.robot.max_speed + bound)
    disturbance = make_disturbance(args.model_disturbance, bound, args.seed, hold)
    result = run_closed_loop(
        executor,
        disturbance,
        bound=bound,
        cycles=cycles,
        duration=duration,
        dt=dt,
        heading=args.heading,
        source=str(args.out),
    )
    verdict = _verify_run(result.trace, args.out)
    if args.output is not None:
        _write(args.output, result.trace)
    document = _report(args, result, verdict, bound, declared)
    reporter = Reporter.for_args(args, out, err)
    if result.progress.status in ("no_plan", "violated"):
        code = EXIT_NEGATIVE
    else:
        code = OUTCOME_EXIT[verdict.outcome]
    reporter.finish(code, document, _text(document))
    if bound > declared:  # after the result, which it qualifies
        reporter.note(
            f"note: the controllers guarantee the task for |w| <= {declared:g} "
            "(robot.disturbance); above it the executor recovers where it can"
        )
    return code


def _verify_run(trace: Mapping[str, Any], out: Path) -> Verdict:
    """The independent verifier's verdict on the run's trace.  Its one refusal, a time bound's
    window meeting too many pieces of a dense lap's copies (V040), is placed at the compile's
    output the run came from, with what this command can change (verify's own hint names
    flags of `tlmpc verify`)."""
    import dataclasses

    from tlmpc.verify import verify_document

    try:
        return verify_document(trace, file=str(out))
    except UsageError as exc:
        raise UsageError(
            [
                dataclasses.replace(
                    d,
                    hint="verify a run with fewer samples: a shorter --duration, fewer "
                    "--cycles, or a larger --dt",
                )
                if d.code == "V040"
                else d
                for d in exc.diagnostics
            ]
        ) from None


def _write(path: Path, document: Any) -> None:
    """Write ``document`` to ``path`` atomically (the one atomic writer: a temporary file
    renamed over it, removed whatever stops the write, Ctrl-C included)."""
    from tlmpc.base.errors import TlmpcError
    from tlmpc.io.outdir import replace_file

    try:
        replace_file(path, dumps(document).encode("utf-8"))
    except TlmpcError as exc:  # the writer's U033/U034, under this command's code
        raise UsageError(
            [error("U083", d.message, hint=d.hint, file=str(path)) for d in exc.diagnostics]
        ) from None


def _report(
    args: argparse.Namespace,
    result: ClosedLoopRun,
    verdict: Verdict,
    bound: float,
    declared: float,
) -> dict[str, Any]:
    progress = result.progress
    samples = result.trace["points"]
    return {
        "out": str(args.out),
        "outcome": verdict.outcome,
        "formula": verdict.formula,
        "robustness": verdict.robustness,
        "ending": result.trace["end"],
        "disturbance": {
            "bound": bound,
            "declared": declared,
            "model": args.model_disturbance,
            "seed": args.seed,
        },
        "dt": result.dt,
        "samples": result.samples,
        "seconds": samples[-1][0],
        "status": progress.status,
        "laps": progress.laps,
        "reentries": progress.reentries,
        "replans": progress.replans,
        "recoveries": [
            {
                "time": r.time,
                "kind": r.kind,
                "triangle": r.triangle,
                "step_before": r.step_before,
                "step_after": r.step_after,
            }
            for r in result.recoveries
        ],
        "completed": result.completed,
        "violations": [v.message for v in verdict.violations],
    }


def _text(report: dict[str, Any]) -> str:
    status = {"satisfied": "satisfied", "violated": "VIOLATED", "inconclusive": "inconclusive"}
    disturbance = report["disturbance"]
    lines = [
        f"{report['out']}: {status[report['outcome']]}: {report['formula']}",
        f"  disturbance |w| <= {disturbance['bound']:g} ({disturbance['model']}, seed "
        f"{disturbance['seed']}); dt {report['dt']:.4g} s, {report['samples']} samples, "
        f"{report['seconds']:.4g} s simulated; trace ends: {report['ending']}",
        f"  executor: {report['status']}, {report['laps']} lap(s) of the cycle, "
        f"{report['reentries']} re-entr{'y' if report['reentries'] == 1 else 'ies'}, "
        f"{report['replans']} re-plan(s)",
    ]
    lines.extend(f"  violation: {violation}" for violation in report["violations"])
    lines.append(f"  robustness: {report['robustness']:.6g}")
    return "\n".join(lines) + "\n"
