"""The benchmark suite: ``python -m bench`` (or ``python bench/run.py``).

Generates the workloads, compiles each in a fresh interpreter (median of ``--repeats`` runs,
peak RSS of the child), runs the per-stage benchmarks of ``bench/bench_*.py``, prints markdown
tables and writes ``bench/results.json``.  See docs/performance.md for what the numbers mean.
"""

from __future__ import annotations

import argparse
import importlib
import json
import platform
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

from bench.tables import markdown_table  # noqa: E402
from bench.workloads import grid_of_rooms, sequence_avoiding, write_mission  # noqa: E402

STAGE_MODULES = (
    "bench.bench_abstraction",
    "bench.bench_automata",
    "bench.bench_planning",
    "bench.bench_control",
    "bench.bench_verify",
)
GRID_SIZES = {"grid-1k": 11, "grid-10k": 35, "grid-100k": 112, "grid-300k": 194}


def _compile_once(mission: Path, out: Path) -> dict[str, Any]:
    completed = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "compile_once.py"), str(mission), str(out)],
        capture_output=True,
        text=True,
        check=False,
        cwd=ROOT,
    )
    if completed.returncode != 0:
        raise RuntimeError(f"{mission}: {completed.stderr[-2000:]}")
    result: dict[str, Any] = json.loads(completed.stdout.strip().splitlines()[-1])
    if result["exit"] != 0:
        raise RuntimeError(f"{mission}: exit {result['exit']}: {result['stderr']}")
    return result


def compile_workload(name: str, mission: Path, repeats: int, scratch: Path) -> dict[str, Any]:
    """Compile ``mission`` ``repeats`` times; medians of every stage and of the total."""
    runs = [_compile_once(mission, scratch / f"{name}-{k}") for k in range(repeats)]
    summaries = [r["summary"] for r in runs]
    stage_names = [s["name"] for s in summaries[0]["stages"]]
    stage_medians = {
        stage: statistics.median(
            next(s["seconds"] for s in summary["stages"] if s["name"] == stage)
            for summary in summaries
        )
        for stage in stage_names
    }
    sizes: dict[str, Any] = {}
    for stage in summaries[0]["stages"]:
        sizes.update({f"{stage['name']}.{k}": v for k, v in stage["sizes"].items()})
    return {
        "workload": name,
        "mission": str(mission.relative_to(ROOT)) if mission.is_relative_to(ROOT) else mission.name,
        "repeats": repeats,
        "stage_seconds": stage_medians,
        "pipeline_seconds": statistics.median(s["total_seconds"] for s in summaries),
        "compile_seconds": statistics.median(r["compile_seconds"] for r in runs),
        "cold_seconds": statistics.median(r["cold_seconds"] for r in runs),
        "peak_rss_mb": max(r["peak_rss_mb"] for r in runs),
        "sizes": sizes,
    }


def _compile_table(rows: list[dict[str, Any]]) -> str:
    stages = ["load", "abstraction", "automaton", "plan", "control", "simulate", "verify"]
    header = (
        "| workload | triangles | aut. states | product nodes (reached) | witness | "
        + " | ".join(stages)
        + " | plot | pipeline s | compile s | cold s | peak MB |"
    )
    lines = [header, "|" + "---|" * (len(stages) + 10)]
    for row in rows:
        sizes = row["sizes"]
        witness = f"{sizes.get('plan.prefix', '?')}+{sizes.get('plan.cycle', '?')}"
        cells = [f"{row['stage_seconds'].get(s, float('nan')):.3f}" for s in [*stages, "plot"]]
        lines.append(
            f"| {row['workload']} | {sizes.get('abstraction.triangles', '?')} | "
            f"{sizes.get('automaton.states', '?')} | "
            f"{sizes.get('plan.product nodes', '?')} ({sizes.get('plan.reached', '?')}) | "
            f"{witness} | "
            + " | ".join(cells)
            + f" | {row['pipeline_seconds']:.3f} | {row['compile_seconds']:.3f} | "
            f"{row['cold_seconds']:.2f} | {row['peak_rss_mb']:.0f} |"
        )
    return "\n".join(lines)


def stage_tables(name: str, rows: list[dict[str, Any]] | dict[str, list[dict[str, Any]]]) -> str:
    """A stage benchmark's markdown: one table, or one per part when it returns several."""
    if isinstance(rows, dict):
        return "".join(
            f"## {name}: {part}\n\n{markdown_table(part_rows)}\n\n"
            for part, part_rows in rows.items()
        )
    return f"## {name}\n\n{markdown_table(rows)}\n\n"


def main(argv: list[str] | None = None) -> int:
    """Run the suite; ``--quick`` skips the 300k grid and uses one repeat."""
    parser = argparse.ArgumentParser(prog="python -m bench", description=__doc__)
    parser.add_argument("--repeats", type=int, default=3, help="runs per workload (median)")
    parser.add_argument("--quick", action="store_true", help="one repeat, no 300k grid")
    parser.add_argument(
        "--only", choices=("compile", "stages"), help="run only one part of the suite"
    )
    parser.add_argument(
        "--results", type=Path, default=ROOT / "bench" / "results.json", help="JSON output"
    )
    args = parser.parse_args(argv)
    repeats = 1 if args.quick else args.repeats

    report: dict[str, Any] = {
        "machine": {
            "python": platform.python_version(),
            "platform": platform.platform(),
            "processor": platform.processor() or platform.machine(),
            "cpus": __import__("os").cpu_count(),
        },
        "date": time.strftime("%Y-%m-%d"),
        "repeats": repeats,
    }
    with tempfile.TemporaryDirectory(prefix="tlmpc-bench-") as tmp:
        scratch = Path(tmp)
        if args.only in (None, "compile"):
            workloads: list[tuple[str, Path]] = [
                (name, ROOT / "specs" / f"{name}.yaml")
                for name in ("example1", "example6", "example7", "example8")
            ]
            for name, n in GRID_SIZES.items():
                if args.quick and n > 120:
                    continue
                workloads.append((name, write_mission(grid_of_rooms(n), scratch)))
            workloads.append(("sequence-10-avoid-50", write_mission(sequence_avoiding(), scratch)))
            rows = []
            for name, mission in workloads:
                print(f"compiling {name} ...", file=sys.stderr, flush=True)
                rows.append(compile_workload(name, mission, repeats, scratch))
            report["compile"] = rows
            print("## Whole compile (median seconds per stage)\n")
            print(_compile_table(rows) + "\n")
        if args.only in (None, "stages"):
            report["stages"] = {}
            for module_name in STAGE_MODULES:
                try:
                    module = importlib.import_module(module_name)
                except ModuleNotFoundError:
                    continue
                print(f"running {module_name} ...", file=sys.stderr, flush=True)
                stage_rows = module.run(repeats=max(repeats, 3) if not args.quick else 1)
                name = module_name.split(".")[-1]
                report["stages"][name] = stage_rows
                print(stage_tables(name, stage_rows))
    args.results.write_text(json.dumps(report, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    print(f"results written to {args.results}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
