"""Writing the artifacts, before and after: CPU seconds of ``write_artifacts`` on the grid maps.

``python bench/bench_artifacts.py --baseline DIR`` compiles each workload (Example 8 and the
``bench.workloads.grid_of_rooms`` maps named by ``--grids``) in a fresh interpreter per tree
and per round (rounds interleaved across the trees, as ``bench_stages.py`` does; the figure
is not drawn), then writes every artifact into a temporary folder as ``tlmpc compile`` does
and prints the median CPU seconds of that writing (the JSON text of every document and the
files), the artifacts' total size and a digest of their bytes with the timings masked (the
digests of the trees must agree: the same artifacts, byte for byte).
"""

from __future__ import annotations

import statistics
import sys
import tempfile
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bench.bench_stages import _run, comparison_parser, trees_of, workloads_of

#: Run in a fresh interpreter: every stage but the figure, then the writing, timed.
WRITE_PROGRAM = """
import gc, hashlib, json, re, sys, tempfile, time
from pathlib import Path
gc.disable()
from tlmpc.io.outdir import write_artifacts
from tlmpc.pipeline.stages import STAGES, Compilation, run_stages
compilation = Compilation(source=Path(sys.argv[1]), text=None, figures=())
for stage in STAGES:
    if stage.name != "plot":
        compilation = run_stages([stage], compilation).compilation
artifacts = dict(compilation.documents)
with tempfile.TemporaryDirectory() as folder:
    before = time.process_time()
    write_artifacts(Path(folder), artifacts)
    cpu = time.process_time() - before
    digest = hashlib.sha256()
    size = 0
    timing = re.compile(rb'("[a-z_]*seconds"\\s*:\\s*)[-0-9.e+]+')
    for path in sorted(Path(folder).iterdir()):
        data = path.read_bytes()
        size += len(data)
        digest.update(path.name.encode() + timing.sub(rb"\\1T", data))
print(json.dumps({"cpu": cpu, "bytes": size, "digest": digest.hexdigest()[:16]}))
"""


def main(argv: list[str] | None = None) -> int:
    args = comparison_parser("bench_artifacts.py", __doc__, rounds=5).parse_args(argv)
    trees = trees_of(args)
    with tempfile.TemporaryDirectory(prefix="tlmpc-write-") as tmp:
        workloads = workloads_of(args.grids, Path(tmp))
        print("| workload | tree | write CPU s (median) | artifacts MB | digest (timings masked) |")
        print("|---|---|---:|---:|---|")
        for workload, path in workloads.items():
            runs: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
            for _ in range(args.rounds):
                for name, tree in trees.items():
                    print(f"{workload} {name} ...", file=sys.stderr, flush=True)
                    runs[name].append(_run(tree, WRITE_PROGRAM, str(path)))
            for name, results in runs.items():
                cpu = statistics.median(r["cpu"] for r in results)
                print(
                    f"| {workload} | {name} | {cpu:.3f} | {results[0]['bytes'] / 1e6:.2f} | "
                    f"{results[0]['digest']} |"
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
