"""Side by side: the shipped specs compiled by this tree and by a baseline tree.

    python bench/bench_completeness.py BASELINE_ROOT [--repeats 5]

For every ``specs/*.yaml`` (and the dead-end mission that needs a U-turn) each tree compiles the
mission in its own fresh interpreter (``compile_mission`` up to ``verify``, nothing written),
alternating trees round by round so that machine load hits both alike.  Prints the final
triangle count (after any U-turn splits) and the median compile CPU seconds per tree
(process time: on a shared machine wall time mostly measures the other processes).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

DEAD_END = """\
version: 1
name: dead-end
workspace:
  boundary: [[0, 0], [10, 0], [10, 4], [6, 4], [6, 10], [5, 10], [5, 4], [0, 4]]
regions:
  tip: {rect: [5, 9, 6, 10]}
  base: {rect: [0, 0, 2, 2]}
robot: {start: [9, 1], max_speed: 1.0}
task: [visit tip then base]
"""

CHILD = """\
import json, sys, time
sys.path.insert(0, sys.argv[1])
from tlmpc.base.errors import TlmpcError
from tlmpc.pipeline.stages import ABSTRACTION, compile_mission
compile_mission(sys.argv[2], until="verify")  # warm the imports and caches
rows = {}
for path in sys.argv[2:]:
    started = time.process_time()
    try:
        result = compile_mission(path, until="verify")
        triangles = result.compilation.get(ABSTRACTION).num_triangles
    except TlmpcError as exc:
        triangles = exc.diagnostics[0].code
    rows[path] = [triangles, time.process_time() - started]
print(json.dumps(rows))
"""


def _run(root: Path, missions: list[str]) -> dict[str, list[object]]:
    done = subprocess.run(
        [sys.executable, "-c", CHILD, str(root), *missions],
        capture_output=True,
        text=True,
        check=True,
        cwd=root,
        env={"PATH": "/usr/bin:/bin", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"},
    )
    rows: dict[str, list[object]] = json.loads(done.stdout.strip().splitlines()[-1])
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("baseline", type=Path)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    scratch = Path(tempfile.mkdtemp())
    (scratch / "dead-end.yaml").write_text(DEAD_END)
    missions = [str(p) for p in sorted((ROOT / "specs").glob("*.yaml"))]
    missions.append(str(scratch / "dead-end.yaml"))
    trees = {"baseline": args.baseline.resolve(), "this tree": ROOT}
    runs: dict[str, list[dict[str, list[object]]]] = {name: [] for name in trees}
    for _ in range(args.repeats):
        for name, root in trees.items():
            runs[name].append(_run(root, missions))
    print(
        "| mission | triangles (baseline) | triangles (this tree) "
        "| CPU s (baseline) | CPU s (this tree) | change |"
    )
    print("|---|---|---|---|---|---|")
    for mission in missions:
        tri = {n: runs[n][0][mission][0] for n in trees}
        med = {n: statistics.median(float(r[mission][1]) for r in runs[n]) for n in trees}  # type: ignore[arg-type]
        change = med["this tree"] / med["baseline"] - 1.0
        print(
            f"| {Path(mission).name} | {tri['baseline']} | {tri['this tree']} | "
            f"{med['baseline']:.4f} | {med['this tree']:.4f} | {change:+.1%} |"
        )


if __name__ == "__main__":
    main()
