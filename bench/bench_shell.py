"""What a user feels: tlmpc from the shell, side by side with SPIN, and how it scales.

``python bench/bench_shell.py`` prints, from one run (medians, measured interleaved so that
the machine's load hits every column alike):

1. Example 8 compiled from the shell: tlmpc cold (a fresh ``python -m tlmpc compile``, the
   interpreter's start-up included) and warm (a second compile in the same interpreter),
   beside SPIN's planning pipeline on the same model (export + ``spin -a`` + ``gcc`` +
   ``./pan -a``, as ``bench_planning.py`` runs it).  ``--baseline DIR`` adds another tlmpc
   source tree (e.g. an older commit) measured in the same rounds: before and after.
2. ``tlmpc check`` of one mission and of 1,000 missions in one call.
3. The import breakdown of a cold compile (``python -X importtime``), by top-level package.
4. Each stage of Example 8 and the peak memory.
5. The scaling curve on grid maps (10k, 100k, 300k, 1M triangles) with fitted growth
   exponents of time and peak memory (least squares on log-log), for the baseline tree too;
   a refused compile (e.g. the planner's product budget at 1M) is shown with its diagnostic.

CPU seconds are printed beside wall seconds: on a shared machine they move less.
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench.workloads import grid_of_rooms, write_mission  # noqa: E402

#: Grid sizes n (n x n rooms; 8 n^2 + 2 triangles) of the scaling curve.
SCALING = {"10k": 35, "100k": 112, "300k": 194, "1M": 354}


def _environment(tree: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    # An installed package has its bytecode compiled; a source tree in a CI job may forbid
    # writing it, which would add the compilation of every module to every start.
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _prepare(tree: Path) -> None:
    subprocess.run(
        [sys.executable, "-m", "compileall", "-q", str(tree / "tlmpc")],
        check=True,
        env=_environment(tree),
        capture_output=True,
    )


def _run(tree: Path, argv: list[str], cwd: Path) -> dict[str, Any]:
    """Run ``tlmpc ARGV`` in a fresh interpreter; wall seconds of the whole process."""
    started = time.perf_counter()
    done = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "compile_cold.py"), *argv],
        capture_output=True,
        text=True,
        env=_environment(tree),
        cwd=cwd,
        check=False,
    )
    wall = time.perf_counter() - started
    if done.returncode != 0 or not done.stdout.strip():
        raise RuntimeError(f"tlmpc {' '.join(argv)}: {done.stderr[-2000:]}")
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    result["wall_seconds"] = wall
    return result


def _warm(tree: Path, mission: Path, out: Path, cwd: Path) -> float:
    """The second compile of ``mission`` in one interpreter (libraries loaded)."""
    program = (
        "import io, sys, time\n"
        "from tlmpc.cli import main\n"
        "args = ['compile', sys.argv[1], '-o', sys.argv[2], '-q', '--force']\n"
        "main(args, io.StringIO(), io.StringIO())\n"
        "t = time.perf_counter()\n"
        "main(args, io.StringIO(), io.StringIO())\n"
        "print(time.perf_counter() - t)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", program, str(mission), str(out)],
        capture_output=True,
        text=True,
        env=_environment(tree),
        cwd=cwd,
        check=True,
    )
    return float(done.stdout.strip().splitlines()[-1])


def _spin_pipeline(mission: Path, scratch: Path) -> dict[str, float] | None:
    """Export + spin -a + gcc + pan (first trail) on the model of ``mission``."""
    from bench.bench_planning import spin_runner
    from tlmpc.abstraction import build_abstraction
    from tlmpc.mission import load_mission

    spin = spin_runner()
    from tlmpc.planning.export import to_promela

    if not spin.available():
        return None
    loaded = load_mission(mission)
    abstraction = build_abstraction(loaded)
    work = Path(tempfile.mkdtemp(dir=scratch))
    model = work / "model.pml"
    started = time.perf_counter()
    model.write_text(to_promela(abstraction, loaded.formula, mission.stem))
    export = time.perf_counter() - started
    trail = spin.run_spin(model, timeout=900, max_depth=10_000_000)
    seconds = {"export": export, **{k: v for k, v in trail.seconds.items() if k != "spin -t"}}
    seconds["total"] = sum(seconds.values())
    shutil.rmtree(work, ignore_errors=True)
    return seconds


def _median(values: list[float]) -> float:
    return statistics.median(values) if values else math.nan


def _interleaved(rounds: int, columns: dict[str, Callable[[], Any]]) -> dict[str, list[Any]]:
    """Run every column once per round, in turn: load spikes spread over all columns."""
    results: dict[str, list[Any]] = {name: [] for name in columns}
    for _ in range(rounds):
        for name, function in columns.items():
            results[name].append(function())
    return results


def _import_breakdown(tree: Path, mission: Path, out: Path, cwd: Path) -> list[tuple[str, float]]:
    program = (
        "import io, sys\nfrom tlmpc.cli import main\n"
        "main(['compile', sys.argv[1], '-o', sys.argv[2], '-q', '--force'], io.StringIO(), "
        "io.StringIO())\n"
    )
    done = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", program, str(mission), str(out)],
        capture_output=True,
        text=True,
        env=_environment(tree),
        cwd=cwd,
        check=True,
    )
    totals: dict[str, float] = {}
    for line in done.stderr.splitlines():
        if not line.startswith("import time:") or "self [us]" in line:
            continue
        self_us, _cumulative, name = line.split(":", 1)[1].split("|")
        top = name.strip().split(".")[0]
        totals[top] = totals.get(top, 0.0) + float(self_us) / 1e6
    return sorted(totals.items(), key=lambda item: -item[1])


def _check_missions(directory: Path, count: int) -> list[Path]:
    """``count`` small valid missions (Example 1 moved around), for ``tlmpc check``."""
    source = (ROOT / "specs" / "example1.yaml").read_text(encoding="utf-8")
    paths = []
    for k in range(count):
        path = directory / f"m{k:04d}.yaml"
        path.write_text(
            source.replace("name: paper-example-1", f"name: check-{k}").replace(
                "start: [1.5, 1.5]", f"start: [{1.0 + (k % 7) * 0.2:.1f}, 1.5]"
            ),
            encoding="utf-8",
        )
        paths.append(path)
    return paths


def _fit(xs: list[float], ys: list[float]) -> float:
    """Least-squares slope of log y against log x (the growth exponent)."""
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = statistics.fmean(lx), statistics.fmean(ly)
    denominator = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly, strict=True)) / denominator


STAGE_COLUMNS = ("load", "abstraction", "plan", "control", "simulate", "verify", "plot")


def _stage_seconds(run: dict[str, Any], name: str) -> float:
    return next((s["seconds"] for s in run["summary"]["stages"] if s["name"] == name), math.nan)


def _scaling(
    grids: list[str], trees: dict[str, Path], scratch: Path, repeats: int
) -> dict[str, list[tuple[int, float, float, float]]]:
    """The scaling table: every tree on every grid, interleaved round by round."""
    print("\n## Scaling on grid maps (fresh interpreter per run, median)\n")
    print(
        "| grid | tree | triangles | product nodes | wall s | CPU s | peak MB | "
        + " | ".join(STAGE_COLUMNS)
        + " |"
    )
    print("|---|---|---:|---:|---:|---:|---:|" + "---:|" * len(STAGE_COLUMNS))
    points: dict[str, list[tuple[int, float, float, float]]] = {name: [] for name in trees}
    for label in grids:
        n = SCALING[label]
        mission = write_mission(grid_of_rooms(n), scratch)
        columns: dict[str, Callable[[], Any]] = {
            name: functools.partial(
                _run,
                tree,
                ["compile", str(mission), "-o", str(scratch / f"g{n}-{name}"), "-q", "--force"],
                scratch,
            )
            for name, tree in trees.items()
        }
        print(f"grid {label} ...", file=sys.stderr, flush=True)
        results = _interleaved(repeats if n <= 200 else 1, columns)
        for name, runs in results.items():
            wall = _median([r["wall_seconds"] for r in runs])
            cpu = _median([r["cpu_seconds"] for r in runs])
            peak = max(r["peak_rss_mb"] for r in runs)
            if any(r["summary"] is None for r in runs):
                # A refusal (e.g. the planner's product budget) or a failure: say which.
                failed = next(r for r in runs if r["summary"] is None)
                first = failed["stderr"].strip().splitlines()[:1]
                print(
                    f"| {label} | {name} | - | - | {wall:.2f} | {cpu:.2f} | {peak:.0f} | "
                    f"exit {failed['exit']}: {first[0] if first else ''} |"
                )
                continue
            stage = {s["name"]: s for s in runs[-1]["summary"]["stages"]}
            triangles = stage["abstraction"]["sizes"]["triangles"]
            points[name].append((triangles, wall, cpu, peak))
            cells = [f"{_median([_stage_seconds(r, c) for r in runs]):.2f}" for c in STAGE_COLUMNS]
            nodes = stage["plan"]["sizes"].get("product nodes", "?")
            print(
                f"| {label} | {name} | {triangles:,} | {nodes:,} | {wall:.2f} | {cpu:.2f} | "
                f"{peak:.0f} | " + " | ".join(cells) + " |"
            )
    for name, curve in points.items():
        if len(curve) >= 2:
            xs = [float(p[0]) for p in curve]
            print(
                f"\nGrowth exponents of {name} (time ~ triangles^k, least squares on log-log): "
                f"wall {_fit(xs, [p[1] for p in curve]):.2f}, "
                f"CPU {_fit(xs, [p[2] for p in curve]):.2f}, "
                f"peak memory {_fit(xs, [p[3] for p in curve]):.2f}"
            )
    return points


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python bench/bench_shell.py", description=__doc__)
    parser.add_argument("--rounds", type=int, default=5, help="rounds of the side-by-side runs")
    parser.add_argument("--baseline", type=Path, help="another tlmpc source tree to compare")
    parser.add_argument(
        "--scaling",
        default="10k,100k,300k,1M",
        help="grid sizes of the scaling curve (of: " + ", ".join(SCALING) + "; empty: none)",
    )
    parser.add_argument("--scaling-rounds", type=int, default=3, help="runs per grid (median)")
    parser.add_argument("--no-spin", action="store_true", help="skip SPIN")
    parser.add_argument("--json", type=Path, help="also write the numbers as JSON here")
    args = parser.parse_args(argv)

    report: dict[str, Any] = {"date": time.strftime("%Y-%m-%d %H:%M"), "cpus": os.cpu_count()}
    trees = {"tlmpc": ROOT}
    if args.baseline is not None:
        trees["baseline"] = args.baseline.resolve()
    for tree in trees.values():
        _prepare(tree)
    example8 = ROOT / "specs" / "example8.yaml"
    with tempfile.TemporaryDirectory(prefix="tlmpc-shell-") as tmp:
        scratch = Path(tmp)
        columns: dict[str, Callable[[], Any]] = {}
        for name, tree in trees.items():
            out = scratch / f"{name}-out"
            columns[f"{name} cold"] = functools.partial(
                _run, tree, ["compile", str(example8), "-o", str(out), "-q", "--force"], scratch
            )
        if not args.no_spin:
            columns["spin"] = functools.partial(_spin_pipeline, example8, scratch)
        print(f"Example 8 side by side, {args.rounds} rounds ...", file=sys.stderr, flush=True)
        rounds = _interleaved(args.rounds, columns)
        warm = {
            name: _median(
                [_warm(tree, example8, scratch / f"{name}-warm", scratch) for _ in range(3)]
            )
            for name, tree in trees.items()
        }

        rows = []
        spin_total = None
        if rounds.get("spin") and rounds["spin"][0] is not None:
            spin_total = _median([r["total"] for r in rounds["spin"]])
            phases = {k: _median([r[k] for r in rounds["spin"]]) for k in rounds["spin"][0]}
            report["spin"] = phases
        for name in trees:
            runs = rounds[f"{name} cold"]
            row = {
                "tree": name,
                "cold wall s": _median([r["wall_seconds"] for r in runs]),
                "cold cpu s": _median([r["cpu_seconds"] for r in runs]),
                "warm s": warm[name],
                "peak MB": max(r["peak_rss_mb"] for r in runs),
            }
            if spin_total is not None:
                row["cold / SPIN"] = row["cold wall s"] / spin_total
            rows.append(row)
        report["example8"] = rows
        print(f"## Example 8 from the shell (median of {args.rounds} rounds, interleaved)\n")
        print("| tree | cold wall s | cold CPU s | warm s | peak MB | cold / SPIN |")
        print("|---|---:|---:|---:|---:|---:|")
        for row in rows:
            ratio = f"{row['cold / SPIN']:.3f}" if "cold / SPIN" in row else "-"
            print(
                f"| {row['tree']} | {row['cold wall s']:.3f} | {row['cold cpu s']:.3f} | "
                f"{row['warm s']:.3f} | {row['peak MB']:.0f} | {ratio} |"
            )
        if "spin" in report:
            phases = report["spin"]
            print(
                "\nSPIN's pipeline on the same model (median): "
                + ", ".join(f"{k} {v:.3f} s" for k, v in phases.items())
            )
        if len(rows) == 2:
            print(
                f"\ncold wall ratio tlmpc / baseline: {rows[0]['cold wall s'] / rows[1]['cold wall s']:.2f}"  # noqa: E501
                f"; CPU ratio: {rows[0]['cold cpu s'] / rows[1]['cold cpu s']:.2f}"
            )

        # --- tlmpc check ------------------------------------------------------------------
        missions = _check_missions(scratch, 1000)
        check_columns: dict[str, Callable[[], Any]] = {}
        for name, tree in trees.items():
            check_columns[f"{name} one"] = functools.partial(
                _run, tree, ["check", str(missions[0])], scratch
            )
            check_columns[f"{name} 1000"] = functools.partial(
                _run, tree, ["check", *map(str, missions)], scratch
            )
        print("`tlmpc check` ...", file=sys.stderr, flush=True)
        checks = _interleaved(args.rounds, check_columns)
        print("\n## `tlmpc check` from the shell (median)\n")
        print("| tree | 1 mission wall s | CPU s | 1,000 missions wall s | CPU s |")
        print("|---|---:|---:|---:|---:|")
        report["check"] = {}
        for name in trees:
            one, many = checks[f"{name} one"], checks[f"{name} 1000"]
            cells = [
                _median([r["wall_seconds"] for r in one]),
                _median([r["cpu_seconds"] for r in one]),
                _median([r["wall_seconds"] for r in many]),
                _median([r["cpu_seconds"] for r in many]),
            ]
            report["check"][name] = cells
            print(f"| {name} | " + " | ".join(f"{c:.3f}" for c in cells) + " |")

        # --- imports and stages -----------------------------------------------------------
        print("\n## Imports of a cold Example 8 compile (python -X importtime, self time)\n")
        print("| package | seconds |")
        print("|---|---:|")
        breakdown = _import_breakdown(ROOT, example8, scratch / "imports", scratch)
        report["imports"] = breakdown
        for package, seconds in breakdown[:14]:
            print(f"| {package} | {seconds:.3f} |")
        print(f"| (all) | {sum(s for _, s in breakdown):.3f} |")
        last = rounds["tlmpc cold"][-1]["summary"]
        print("\n## Stages of Example 8 (last cold run)\n")
        print("| stage | seconds | sizes |")
        print("|---|---:|---|")
        for stage in last["stages"]:
            sizes = ", ".join(f"{k} {v}" for k, v in stage["sizes"].items() if k != "formula")
            print(f"| {stage['name']} | {stage['seconds']:.3f} | {sizes} |")

        # --- scaling ----------------------------------------------------------------------
        grids = [s for s in args.scaling.split(",") if s]
        if grids:
            report["scaling"] = _scaling(grids, trees, scratch, args.scaling_rounds)
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2, default=str) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
