"""Planning benchmark: the paper's Example 8 map, cover-n and patrol-n, and SPIN side by side.

``python bench/bench_planning.py`` prints a markdown table.  With SPIN (and gcc) installed, the
same transition system and negated task go through ``tlmpc export --format promela``,
``spin -a``, ``gcc`` and ``./pan -a``, each phase timed, against tlmpc's planning time.
"""

from __future__ import annotations

import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

ROOMS = ["r31_13", "r12_30", "r5_28", "r28_4", "r20_20", "r2_17", "r17_2", "r33_33"]


def _median_time(function: Any, repeats: int) -> tuple[float, Any]:
    times = []
    result = None
    for _ in range(repeats):
        started = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - started)
    return statistics.median(times), result


def _example8() -> tuple[Any, Any]:
    from tlmpc.abstraction import build_abstraction
    from tlmpc.mission import load_mission

    mission = load_mission(ROOT / "specs" / "example8.yaml")
    return mission, build_abstraction(mission)


def planning_rows(repeats: int) -> list[dict[str, Any]]:
    """Translate + plan on the Example 8 map for the paper's task, cover-n and patrol-n."""
    from tlmpc.automata import translate
    from tlmpc.ltl import parse_ltl
    from tlmpc.planning import plan

    mission, abstraction = _example8()
    tasks = [("paper: F a & F b", str(mission.formula))]
    tasks += [(f"cover-{n}", " & ".join(f"F {r}" for r in ROOMS[:n])) for n in range(2, 9)]
    tasks += [(f"patrol-{n}", " & ".join(f"G F {r}" for r in ROOMS[:n])) for n in range(2, 9)]
    rows = []
    for name, text in tasks:
        formula = parse_ltl(text)

        def run(formula: Any = formula) -> Any:
            automaton = translate(formula, letters=abstraction.letters)
            witness = plan(
                abstraction,
                automaton,
                formula=formula,
                options=mission.options,
                start_point=mission.robot.start,
            )
            return automaton, witness

        seconds, (automaton, witness) = _median_time(run, repeats)
        rows.append(
            {
                "workload": f"example8 {name}",
                "triangles": abstraction.num_triangles,
                "automaton states": automaton.num_states,
                "product nodes": witness.stats["product_nodes"],
                "witness": f"{len(witness.prefix)}+{len(witness.cycle)}",
                "optimal": witness.stats["optimal"],
                "plan s (median)": round(seconds, 4),
            }
        )
    return rows


def _timed(command: list[str], cwd: Path, timeout: float) -> tuple[float, str]:
    """Run ``command``; on timeout kill its whole process group (gcc leaves cc1 behind)."""
    started = time.perf_counter()
    process = subprocess.Popen(
        command,
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    try:
        output, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        raise
    return time.perf_counter() - started, output


def spin_rows(repeats: int, timeout: float = 180.0) -> list[dict[str, Any]]:
    """SPIN on the exported model versus tlmpc's planning, per phase."""
    if shutil.which("spin") is None or shutil.which("gcc") is None:
        return [{"workload": "spin", "note": "spin or gcc not installed: skipped"}]
    from tlmpc.abstraction import build_abstraction
    from tlmpc.automata import translate
    from tlmpc.mission import load_mission
    from tlmpc.planning import plan
    from tlmpc.planning.export import to_promela

    rows = []
    for spec in ("example1", "example7", "example8"):
        mission = load_mission(ROOT / "specs" / f"{spec}.yaml")
        abstraction = build_abstraction(mission)

        def ours(mission: Any = mission, abstraction: Any = abstraction) -> Any:
            automaton = translate(mission.formula, letters=abstraction.letters)
            return plan(
                abstraction,
                automaton,
                formula=mission.formula,
                options=mission.options,
                start_point=mission.robot.start,
            )

        seconds, witness = _median_time(ours, repeats)
        with tempfile.TemporaryDirectory() as tmp:
            work = Path(tmp)
            started = time.perf_counter()
            (work / "model.pml").write_text(to_promela(abstraction, mission.formula, spec))
            export = time.perf_counter() - started
            try:
                generate, _ = _timed(["spin", "-a", "model.pml"], work, timeout)
                compile_, _ = _timed(
                    ["gcc", "-O2", "-DNOREDUCE", "-o", "pan", "pan.c"], work, timeout
                )
                search, output = _timed(["./pan", "-a", "-m1000000"], work, timeout)
                found = "acceptance cycle" in output or "errors: 1" in output
                total = export + generate + compile_ + search
                rows.append(
                    {
                        "workload": spec,
                        "triangles": abstraction.num_triangles,
                        "tlmpc plan s": round(seconds, 4),
                        "export s": round(export, 4),
                        "spin -a s": round(generate, 3),
                        "gcc s": round(compile_, 3),
                        "pan -a s": round(search, 3),
                        "spin total s": round(total, 3),
                        "speed-up": round(total / seconds, 1),
                        "both find a plan": found and bool(witness.cycle),
                    }
                )
            except subprocess.TimeoutExpired:
                rows.append({"workload": spec, "note": f"spin phase timed out ({timeout} s)"})
    return rows


def run(repeats: int = 3) -> list[dict[str, Any]]:
    """All rows (for bench/run.py)."""
    return planning_rows(repeats) + spin_rows(repeats)


if __name__ == "__main__":
    from bench.tables import markdown_table

    print(markdown_table(planning_rows(3)))
    print()
    print(markdown_table(spin_rows(3)))
