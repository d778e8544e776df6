"""``tlmpc simulate OUT --sensors random|adversarial|FILE`` for a compiled reactive mission.

The strategy in ``OUT/strategy.json`` is run by the reactive executor against an environment
that keeps the mission's assumptions, for ``--events`` events; the trace (positions, sensor
and action signals, the assumptions and the task) is written with ``-o``.  Exit 0 when the
run finished; 1 when a sensor file breaks an assumption (Q120) or no environment can keep
them (Q121); 2 on bad flags, an unreadable file or an output folder that is not a reactive
compilation.  The trace is verified by the independent verifier: exit 1 also when the
robot broke a guarantee (the run is open, so goals met so far are inconclusive: exit 0).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from tlmpc.base.errors import UsageError, error

if TYPE_CHECKING:
    from tlmpc.verify.model import Verdict


def _events(text: str | None) -> int:
    from tlmpc.runtime.reactive_loop import DEFAULT_EVENTS

    if text is None:
        return DEFAULT_EVENTS
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value <= 0 or str(value) != text.strip().lstrip("+"):
        raise UsageError(
            error(
                "U105",
                f"--events must be a whole number >= 1, not {text!r}",
                hint="the run lasts this many events (sensor changes, arrivals), e.g. --events 200",
            )
        )
    return value


def check_seed(seed: int, drawn: str) -> None:
    """U084 unless ``seed`` is one of the 2**128 seeds of the ``drawn`` thing (a static
    run's disturbance, a reactive run's environment)."""
    if not 0 <= seed < 2**128:
        raise UsageError(
            error(
                "U084",
                f"--seed must be a whole number from 0 to 2**128 - 1, not {seed}",
                hint=f"any seed in range gives a reproducible {drawn}, e.g. --seed 1",
            )
        )


def is_reactive_output(folder: Path) -> bool:
    """Whether ``folder`` holds a reactive mission's compilation: its ``strategy.json``, or
    (an unrealizable mission has none) a ``mission.json`` with sensors.  An unreadable
    ``mission.json`` counts as static: the static run then reports it."""
    from tlmpc.base.errors import TlmpcError
    from tlmpc.io.artifacts import read_artifacts

    if (folder / "strategy.json").exists():
        return True
    try:
        mission = read_artifacts(folder, ("mission.json",)).get("mission.json")
    except TlmpcError:
        return False
    return mission is not None and mission.get("reactive") is not None


def run_reactive_command(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Run a reactive mission's strategy against an environment and report."""
    from tlmpc.base.errors import EXIT_NEGATIVE, EXIT_OK
    from tlmpc.io.report import Reporter
    from tlmpc.runtime.environments import (
        AdversarialEnvironment,
        Environment,
        RandomEnvironment,
        ScriptedEnvironment,
        time_scale,
    )
    from tlmpc.runtime.reactive import REACTIVE_ARTIFACTS, ReactiveExecutor
    from tlmpc.runtime.reactive_loop import run_reactive
    from tlmpc.runtime.sensor_file import read_sensor_file
    from tlmpc.verify import verify_document

    events = _events(args.events)
    if not is_reactive_output(args.out):
        raise UsageError(
            error(
                "U100",
                f"{args.out} has no strategy.json: --sensors and --events are for reactive "
                "missions",
                hint="compile a mission with sensors: (realizable), or drop --sensors/--events",
                file=str(args.out),
            )
        )
    for flag, value in (
        ("--disturbance", args.disturbance),
        ("--cycles", args.cycles),
        ("--duration", args.duration),
        ("--dt", args.dt),
    ):
        if value is not None:
            raise UsageError(
                error(
                    "U100",
                    f"{flag} is for static missions; a reactive run is exact and lasts "
                    "--events events",
                    hint=f"drop {flag}",
                )
            )
    check_seed(args.seed, "environment")
    if args.output is not None:
        from tlmpc.io.outputs import refuse_input_as_output

        refuse_input_as_output(args.output, [args.out / name for name in REACTIVE_ARTIFACTS])
    executor = ReactiveExecutor.from_output(args.out)
    assert executor.mission.reactive is not None
    sensors = executor.machine.sensors
    source = args.sensors or "random"
    scale = time_scale(executor)
    environment: Environment
    if source == "random":
        environment = RandomEnvironment(sensors, args.seed, scale)
    elif source == "adversarial":
        environment = AdversarialEnvironment(sensors, args.seed, scale)
    else:
        path = Path(source)
        environment = ScriptedEnvironment(sensors, read_sensor_file(path, sensors), str(path))
    run = run_reactive(executor, environment, events=events)
    verdict = verify_document(run.trace)
    if args.output is not None:
        _write(args.output, run.trace)
    document = _report(args, run, environment.name, verdict)
    code = EXIT_NEGATIVE if verdict.outcome == "violated" else EXIT_OK
    reporter = Reporter.for_args(args, out, err)
    reporter.finish(code, document, _text(document))
    return code


def _write(path: Path, document: dict[str, Any]) -> None:
    """Write the trace atomically (U083 when it cannot be written, as for a static run)."""
    from tlmpc.base.errors import TlmpcError
    from tlmpc.io.artifacts import dumps
    from tlmpc.io.outdir import replace_file

    try:
        replace_file(path, dumps(document).encode("utf-8"))
    except TlmpcError as exc:
        raise UsageError(
            [error("U083", d.message, hint=d.hint, file=str(path)) for d in exc.diagnostics]
        ) from None


def _report(
    args: argparse.Namespace, run: Any, environment: str, verdict: Verdict
) -> dict[str, Any]:
    from tlmpc.runtime.reactive import executor_summary

    executor = run.executor
    summary = executor_summary(executor)
    trace = run.trace
    return {
        "out": str(args.out),
        "environment": environment,
        "seed": args.seed,
        **({"sensor_file": args.sensors} if environment == "file" else {}),
        "events": summary["events"] - 1,
        "by_kind": summary["by_kind"],
        "stopped": run.stopped,
        "samples": len(trace["points"]),
        "seconds": trace["points"][-1][0],
        "faces_visited": len({e.face for e in executor.events}),
        "controller_solves": summary["solves"],
        "formula": trace["ltl"],
        "assumptions": trace["assumptions"],
        "ending": trace["end"],
        "outcome": verdict.outcome,
        "violations": [v.message for v in verdict.violations],
    }


def _text(report: dict[str, Any]) -> str:
    kinds = ", ".join(f"{count} {kind}" for kind, count in sorted(report["by_kind"].items()))
    why = {
        "events": "the event budget was spent",
        "rest": "the robot rests and nothing changes any more",
    }[report["stopped"]]
    against = (
        f"the readings of {report['sensor_file']}"
        if report["environment"] == "file"
        else f"the {report['environment']} environment (seed {report['seed']})"
    )
    outcome = {
        "satisfied": "satisfied",
        "violated": "VIOLATED",
        "inconclusive": "inconclusive (the run goes on; no guarantee broken so far)",
    }[report["outcome"]]
    return (
        f"{report['out']}: ran {report['events']} event(s) against {against}: {why}\n"
        f"  verified: {outcome}\n"
        + "".join(f"  violation: {v}\n" for v in report["violations"])
        + f"  events: {kinds}\n"
        f"  {report['samples']} samples, {report['seconds']:.4g} s simulated, "
        f"{report['faces_visited']} face(s) visited, {report['controller_solves']} "
        f"controller solve(s); trace ends: {report['ending']}\n"
        f"  task: {report['formula']}\n"
        + "".join(f"  assumed: {a}\n" for a in report["assumptions"])
    )
