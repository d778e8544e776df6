"""Control + simulation benchmark: long plans on the Example 8 map and a corridor.

The paper needed ~90 s of MATLAB for the controllers of a 145-triangle path; this prints the
median seconds of tlmpc's controller program (build + solve) and of the exact simulation.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


def _rows_for(name: str, mission: Any, repeats: int) -> dict[str, Any]:
    from tlmpc.abstraction import build_abstraction
    from tlmpc.automata import translate
    from tlmpc.control import synthesize
    from tlmpc.planning import plan
    from tlmpc.simulate import simulate

    abstraction = build_abstraction(mission)
    automaton = translate(mission.formula, letters=abstraction.letters)
    witness = plan(
        abstraction,
        automaton,
        formula=mission.formula,
        options=mission.options,
        start_point=mission.robot.start,
    )
    synthesize(abstraction, witness, mission.robot)  # warm: clarabel import and first solve
    control_times, simulate_times = [], []
    controllers = None
    for _ in range(repeats):
        started = time.perf_counter()
        controllers = synthesize(abstraction, witness, mission.robot)
        control_times.append(time.perf_counter() - started)
        started = time.perf_counter()
        trace = simulate(abstraction, controllers, mission)
        simulate_times.append(time.perf_counter() - started)
    assert controllers is not None
    control = statistics.median(control_times)
    sim = statistics.median(simulate_times)
    return {
        "workload": name,
        "steps": len(controllers.steps),
        "jumps": len(controllers.jumps),
        "build s": controllers.stats["prepare_seconds"],
        "solve s": controllers.stats["solve_seconds"],
        "controllers s (median)": round(control, 4),
        "simulation s (median)": round(sim, 4),
        "samples": len(trace.times),
        "total s": round(control + sim, 4),
    }


def run(repeats: int = 3) -> list[dict[str, Any]]:
    """Rows for bench/run.py: Example 8 (the paper's map) and a 145-step corridor plan."""
    from tlmpc.mission import load_mission, load_mission_text

    rows = [_rows_for("example8", load_mission(ROOT / "specs" / "example8.yaml"), repeats)]
    corridor = """\
version: 1
name: corridor
workspace: {boundary: {rect: [0, 0, 70, 2]}}
regions: {goal: {rect: [68, 0.5, 69.5, 1.5]}}
robot: {start: [0.5, 1.0]}
task: [visit goal]
options: {min_angle: 30, max_area: 0.5}
"""
    rows.append(_rows_for("corridor", load_mission_text(corridor, "corridor.yaml"), repeats))
    return rows


if __name__ == "__main__":
    from bench.tables import markdown_table

    print(markdown_table(run()))
