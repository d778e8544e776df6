"""Reactive execution: events per second of ``tlmpc simulate --sensors`` against workspace size.

For each mission (the shipped guard and depot specs, and the warehouse of bench_reactive.py
meshed at two sizes with two sensors), the strategy is synthesised once, then played for
``--events`` events against the random and the adversarial environment.  Printed: triangles,
faces, strategy nodes, trace samples, controller solves (vertex programs, one per new route)
and wall seconds of the run (the median of ``--rounds``, fresh executor each time).

    python bench/bench_reactive_runs.py [--events 200] [--rounds 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_reactive import warehouse

from tlmpc.abstraction import build_abstraction
from tlmpc.mission import load_mission, load_mission_text
from tlmpc.mission.model import Mission
from tlmpc.reactive.synthesize import strategy_to_json, synthesize
from tlmpc.runtime.environments import AdversarialEnvironment, RandomEnvironment, time_scale
from tlmpc.runtime.reactive import ReactiveExecutor
from tlmpc.runtime.reactive_loop import run_reactive
from tlmpc.runtime.strategy_machine import StrategyMachine

ROOT = Path(__file__).resolve().parents[1]


def missions() -> list[tuple[str, Mission]]:
    found = [
        (name, load_mission(ROOT / "specs" / "reactive" / f"{name}.yaml"))
        for name in ("guard", "depot")
    ]
    for area in (1.0, 0.1):
        text = yaml.safe_dump(warehouse(area, 2))
        found.append((f"warehouse max_area {area}", load_mission_text(text, "warehouse.yaml")))
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--events", type=int, default=200)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    header = (
        f"{'mission':<26} {'env':<11} {'triangles':>9} {'faces':>5} {'nodes':>6} "
        f"{'samples':>7} {'solves':>6} {'run s':>7} {'events/s':>9}"
    )
    print(header)
    print("-" * len(header))
    for name, mission in missions():
        assert mission.reactive is not None
        abstraction = build_abstraction(mission)
        synthesis = synthesize(mission, abstraction)
        if not synthesis.realizable:
            print(f"{name:<26} unrealizable")
            continue
        strategy = strategy_to_json(synthesis)
        machine = StrategyMachine.of_json(
            strategy, mission.reactive.sensor_names, mission.reactive.actions, "strategy.json"
        )
        for kind in ("random", "adversarial"):
            seconds = []
            for _ in range(args.rounds):
                executor = ReactiveExecutor(
                    mission=mission, abstraction=abstraction, machine=machine
                )
                environment = (RandomEnvironment if kind == "random" else AdversarialEnvironment)(
                    machine.sensors, 0, time_scale(executor)
                )
                started = time.perf_counter()
                run = run_reactive(executor, environment, events=args.events)
                seconds.append(time.perf_counter() - started)
            middle = statistics.median(seconds)
            events = len(run.executor.events) - 1
            print(
                f"{name:<26} {kind:<11} {abstraction.num_triangles:>9} "
                f"{len(strategy['faces']['labels']):>5} {len(strategy['nodes']):>6} "
                f"{len(run.trace['points']):>7} {run.executor.solves:>6} {middle:>7.3f} "
                f"{events / middle:>9.0f}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
