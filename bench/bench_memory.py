"""Memory and CPU of a whole compile at scale, stage by stage, before and after.

``python bench/bench_memory.py --grids 1M --baseline DIR --rounds 3`` runs ``tlmpc compile``'s
own path (every stage, the figure and the artifacts written into a staging directory) in a
fresh interpreter per tree and per round, rounds interleaved across the trees, and prints per
stage the median CPU seconds (``os.times``: user + system of the process) and the resident
set after the stage (``VmRSS``) with the high-water mark so far (``VmHWM``), then the whole
run's CPU seconds and peak RSS (``ru_maxrss``).  Example 8 is always measured too, cold: the
interpreter's start-up and every import included (``--cold-rounds``, median).

``--trace STAGE`` runs one extra child with ``tracemalloc`` on and prints the largest
allocation sites alive at the end of that stage (numpy reports its buffers to tracemalloc),
which is how the big arrays and copies were found.
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench.bench_stages import (  # noqa: E402
    _environment,
    comparison_parser,
    trees_of,
    workloads_of,
)

#: One compile, as ``tlmpc compile`` runs it, measured after every stage.
COMPILE_PROGRAM = """
import gc, json, os, resource, sys, tempfile, time
from pathlib import Path

def cpu():
    t = os.times()
    return t.user + t.system

def status():
    fields = {}
    with open("/proc/self/status") as f:
        for line in f:
            key, _, value = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                fields[key] = int(value.split()[0]) / 1024.0
    return fields

trace_stage = sys.argv[2] if len(sys.argv) > 2 else ""
if trace_stage:
    import tracemalloc
    tracemalloc.start(6)
gc.disable()
from tlmpc.io.outdir import write_artifacts
from tlmpc.pipeline.stages import STAGES, Compilation, run_stages
compilation = Compilation(source=Path(sys.argv[1]), text=None, figures=("svg",))
rows = {"imports": {"cpu": cpu(), **status()}}
artifacts = {}
reports = []
top = []
try:  # one memo for the stages run one at a time, as one compile has
    from tlmpc.base.memo import memo_scope
    memo = memo_scope()
except ImportError:  # a tree from before the memo
    import contextlib
    memo = contextlib.nullcontext()
memo.__enter__()
for stage in STAGES:
    if stage.name == "synthesize":
        continue
    before = cpu()
    result = run_stages([stage], compilation)
    rows[stage.name] = {"cpu": cpu() - before, **status()}
    compilation = result.compilation
    artifacts.update(result.artifacts)
    reports.extend(result.reports)
    if stage.name == trace_stage:
        snapshot = tracemalloc.take_snapshot()
        for stat in snapshot.statistics("traceback")[:12]:
            frames = [f"{f.filename.split('tlmpc/')[-1]}:{f.lineno}" for f in stat.traceback]
            top.append({"mb": stat.size / 2**20, "count": stat.count, "where": frames[::-1]})
        tracemalloc.stop()
before = cpu()
from tlmpc.pipeline.stages import CompileResult
summary = CompileResult(compilation=compilation, artifacts=artifacts, reports=tuple(reports),
                        warnings=()).summary()
artifacts["summary.json"] = summary
with tempfile.TemporaryDirectory() as out:
    write_artifacts(Path(out), artifacts)
rows["write"] = {"cpu": cpu() - before, **status()}
plan = dict(reports[3].sizes) if len(reports) > 3 else {}
print(json.dumps({
    "rows": rows,
    "total": cpu(),
    "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    "plan": plan,
    "top": top,
}))
"""

#: Example 8 from a fresh interpreter, every import included: CPU seconds of the child.
COLD_PROGRAM = """
import io, json, os, resource, sys, tempfile
from tlmpc.cli import main
with tempfile.TemporaryDirectory() as out:
    code = main(["compile", sys.argv[1], "-o", out + "/o", "-q"], io.StringIO(), io.StringIO())
t = os.times()
print(json.dumps({"exit": code, "cpu": t.user + t.system,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0}))
"""

STAGES = (
    "imports",
    "load",
    "abstraction",
    "automaton",
    "plan",
    "control",
    "simulate",
    "verify",
    "plot",
    "write",
)


def _child(tree: Path, program: str, *args: str) -> dict[str, Any]:
    done = subprocess.run(
        [sys.executable, "-c", program, *args],
        capture_output=True,
        text=True,
        env=_environment(tree),
        cwd=tempfile.gettempdir(),
        check=False,
    )
    if done.returncode != 0:
        raise RuntimeError(f"{tree}: {done.stderr[-3000:]}")
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def main(argv: list[str] | None = None) -> int:
    parser = comparison_parser("bench_memory.py", __doc__, rounds=3)
    parser.add_argument("--cold-rounds", type=int, default=5)
    parser.add_argument("--trace", default="", help="tracemalloc's top sites after this stage")
    args = parser.parse_args(argv)
    trees = trees_of(args)
    for tree in trees.values():
        subprocess.run(
            [sys.executable, "-m", "compileall", "-q", str(tree / "tlmpc")],
            env=_environment(tree),
            capture_output=True,
            check=True,
        )
    example8 = str(ROOT / "specs" / "example8.yaml")
    cold: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
    for _ in range(args.cold_rounds):
        for name, tree in trees.items():
            cold[name].append(_child(tree, COLD_PROGRAM, example8))
    print("| Example 8 cold | tree | CPU s (median) | runs | peak MB |")
    print("|---|---|---:|---|---:|")
    for name, runs in cold.items():
        values = [r["cpu"] for r in runs]
        print(
            f"| example8 | {name} | {statistics.median(values):.3f} | "
            + ", ".join(f"{v:.2f}" for v in values)
            + f" | {max(r['peak_mb'] for r in runs):.0f} |"
        )
    with tempfile.TemporaryDirectory(prefix="tlmpc-memory-") as tmp:
        workloads = workloads_of(args.grids, Path(tmp))
        workloads.pop("example8")
        for workload, path in workloads.items():
            runs: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
            for _ in range(args.rounds):
                for name, tree in trees.items():
                    print(f"{workload} {name} ...", file=sys.stderr, flush=True)
                    runs[name].append(_child(tree, COMPILE_PROGRAM, str(path)))
            print(f"\n| {workload} | tree | " + " | ".join(STAGES) + " | total CPU s | peak MB |")
            print("|---|---|" + "---:|" * (len(STAGES) + 2))
            for name, results in runs.items():
                cells = []
                for stage in STAGES:
                    cpu = statistics.median(r["rows"][stage]["cpu"] for r in results)
                    rss = statistics.median(r["rows"][stage]["VmRSS"] for r in results)
                    cells.append(f"{cpu:.2f} s, {rss:.0f} MB")
                print(
                    f"| {workload} | {name} | "
                    + " | ".join(cells)
                    + f" | {statistics.median(r['total'] for r in results):.2f}"
                    + f" | {statistics.median(r['peak_mb'] for r in results):.0f} |"
                )
                print(
                    f"| | {name}: high-water mark after each stage | "
                    + " | ".join(
                        f"{statistics.median(r['rows'][s]['VmHWM'] for r in results):.0f}"
                        for s in STAGES
                    )
                    + f" | | cost {results[0]['plan'].get('cost')} |"
                )
            if args.trace:
                for name, tree in trees.items():
                    traced = _child(tree, COMPILE_PROGRAM, str(path), args.trace)
                    print(f"\n{workload} {name}: largest live allocations after {args.trace}")
                    for entry in traced["top"]:
                        print(  # the innermost frames first: where it was allocated
                            f"  {entry['mb']:8.1f} MB {entry['count']:>8} "
                            + " <- ".join(entry["where"][:4])
                        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
