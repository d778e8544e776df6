"""Planning benchmark: the paper's Example 8 map, cover-n and patrol-n, and SPIN side by side.

``python bench/bench_planning.py`` prints a markdown table.  With SPIN (and gcc) installed, the
same transition system and negated task go through ``tlmpc export --format promela``,
``spin -a``, ``gcc`` and ``./pan -a`` (and the shortest-trail mode ``-DREACH`` + ``./pan -a -i``),
each phase timed, against tlmpc's planning time, with the witness lengths side by side.
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


def spin_runner() -> Any:
    """The tests' SPIN runner (an oracle, not part of the tlmpc package)."""
    oracles = str(ROOT / "tests" / "oracles")
    if oracles not in sys.path:
        sys.path.insert(0, oracles)
    import spin_runner as runner

    return runner


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


def _spin_phase_row(trail: Any, prefix: str) -> dict[str, Any]:
    return {f"{prefix} {phase} s": round(seconds, 3) for phase, seconds in trail.seconds.items()}


def spin_rows(
    repeats: int, timeout: float = 600.0, shortest_timeout: float = 300.0
) -> list[dict[str, Any]]:
    """SPIN on the exported model versus tlmpc's planning: phases, totals, witness lengths.

    Both sides plan over the same D (no-bounce rule in the export) with the same objective:
    tlmpc with ``cost: hops, beta: 1``, SPIN's first trail (``./pan -a``) and its shortest-trail
    mode (``-DREACH``, ``./pan -a -i``).
    """
    spin = spin_runner()

    if not spin.available():
        return [{"workload": "spin", "note": "spin or gcc not installed: skipped"}]
    from dataclasses import replace

    from tlmpc.abstraction import build_abstraction
    from tlmpc.automata import translate
    from tlmpc.mission import load_mission
    from tlmpc.planning import plan
    from tlmpc.planning.export import to_promela

    rows = []
    for spec in ("example1", "example6", "example7", "example8"):
        mission = load_mission(ROOT / "specs" / f"{spec}.yaml")
        abstraction = build_abstraction(mission)
        options = replace(mission.options, cost="hops", beta=1.0)

        def ours(
            mission: Any = mission, abstraction: Any = abstraction, options: Any = options
        ) -> Any:
            automaton = translate(mission.formula, letters=abstraction.letters)
            return plan(
                abstraction,
                automaton,
                formula=mission.formula,
                options=options,
                start_point=mission.robot.start,
            )

        seconds, witness = _median_time(ours, repeats)
        row: dict[str, Any] = {
            "workload": spec,
            "triangles": abstraction.num_triangles,
            "tlmpc plan s": round(seconds, 4),
            "tlmpc hops": round(witness.cost),
        }
        with tempfile.TemporaryDirectory() as tmp:
            model = Path(tmp) / "model.pml"
            started = time.perf_counter()
            model.write_text(to_promela(abstraction, mission.formula, spec))
            row["export s"] = round(time.perf_counter() - started, 4)
            try:
                first = spin.run_spin(model, timeout=timeout, max_depth=10_000_000)
                row |= _spin_phase_row(first, "first:")
                row["first: hops"] = first.moves if first.found else "no plan"
                total = row["export s"] + sum(first.seconds.values()) - first.seconds["spin -t"]
                row["spin total s"] = round(total, 3)
                row["speed-up"] = round(total / seconds, 1)
            except spin.SpinError as failed:
                row["note"] = f"first trail: {failed}"
                rows.append(row)
                continue
            try:
                shortest = spin.run_spin(
                    model, shortest=True, timeout=shortest_timeout, max_depth=10_000_000
                )
                row |= _spin_phase_row(shortest, "shortest:")
                row["shortest: hops"] = shortest.moves if shortest.found else "no plan"
            except spin.SpinError as failed:
                row["note"] = f"shortest trail: {failed}"
        rows.append(row)
    return rows


def run(repeats: int = 3) -> dict[str, list[dict[str, Any]]]:
    """Two tables (for bench/run.py): planning on the Example 8 map, and SPIN side by side."""
    return {"planning": planning_rows(repeats), "spin": spin_rows(repeats)}


if __name__ == "__main__":
    from bench.tables import markdown_table

    print(markdown_table(planning_rows(3)))
    print()
    print(markdown_table(spin_rows(3)))
