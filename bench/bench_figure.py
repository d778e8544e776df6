"""The plot stage, before and after: CPU seconds of ``plan.svg`` from a compile's artifacts.

``python bench/bench_figure.py --baseline DIR`` compiles each workload once (Example 8 and the
``bench.workloads.grid_of_rooms`` maps named by ``--grids``, up to the verify stage, with this
tree), then draws ``plan.svg`` from those artifacts in a fresh interpreter per tree and per
round, rounds interleaved across the trees so that the machine's load hits both alike, and
prints the median CPU seconds (``time.process_time``) of the scene and of the whole picture,
and whether the two trees wrote the same bytes.  The collector is paused as ``tlmpc compile``
pauses it.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bench.bench_stages import ROOT, _environment, _run, comparison_parser, trees_of, workloads_of

#: Run in a fresh interpreter: read the artifacts, then draw the picture ``rounds`` times.
FIGURE_PROGRAM = """
import gc, hashlib, json, sys, time
from pathlib import Path
gc.disable()
directory, rounds = Path(sys.argv[1]), int(sys.argv[2])
documents = {p.name: json.loads(p.read_text()) for p in directory.glob("*.json")}
from tlmpc.render.plot import render_svg
from tlmpc.render.scene import build_scene
render_svg(documents)  # imports and first-call caches: not the stage's work
scene, svg = [], []
for _ in range(rounds):
    before = time.process_time()
    build_scene(documents)
    scene.append(time.process_time() - before)
    before = time.process_time()
    data = render_svg(documents)
    svg.append(time.process_time() - before)
print(json.dumps({"scene": min(scene), "svg": min(svg),
                  "sha256": hashlib.sha256(data).hexdigest(), "bytes": len(data)}))
"""

COMPILE_PROGRAM = """
import sys
from tlmpc.cli import main
sys.exit(main(["compile", sys.argv[1], "-o", sys.argv[2], "-q", "--until", "verify"]))
"""


def main(argv: list[str] | None = None) -> int:
    args = comparison_parser("bench_figure.py", __doc__, rounds=5).parse_args(argv)
    trees = trees_of(args)
    with tempfile.TemporaryDirectory(prefix="tlmpc-figure-") as tmp:
        workloads = workloads_of(args.grids, Path(tmp))
        print("| workload | tree | scene CPU s | scene + SVG CPU s | bytes | same bytes |")
        print("|---|---|---:|---:|---:|---|")
        for workload, path in workloads.items():
            out = Path(tmp) / workload.replace(" ", "-")
            subprocess.run(
                [sys.executable, "-c", COMPILE_PROGRAM, str(path), str(out)],
                env=_environment(ROOT),
                cwd=tempfile.gettempdir(),
                check=True,
            )
            runs: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
            for _ in range(args.rounds):
                for name, tree in trees.items():
                    print(f"{workload} {name} ...", file=sys.stderr, flush=True)
                    runs[name].append(_run(tree, FIGURE_PROGRAM, str(out), "3"))
            digests = {results[0]["sha256"] for results in runs.values()}
            for name, results in runs.items():
                print(
                    f"| {workload} | {name} | "
                    f"{statistics.median(r['scene'] for r in results):.3f} | "
                    f"{statistics.median(r['svg'] for r in results):.3f} | "
                    f"{results[0]['bytes']} | {'yes' if len(digests) == 1 else 'NO'} |"
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
