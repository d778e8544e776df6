"""Side by side: the shipped specs compiled by this tree and by a baseline tree.

    python bench/bench_completeness.py BASELINE_ROOT [--repeats 5]

For every ``specs/*.yaml`` and two dead-end missions (a strip one unit wide, planned on the
default quality mesh, and the same strip on the coarse mesh, ``min_angle: null`` and
``goal_depth: 0``, where the strip is one triangle wide and the plan needs a U-turn) each tree
compiles the mission in its own fresh interpreter (``compile_mission`` up to ``verify``,
nothing written), alternating trees round by round so that machine load hits both alike.
Prints the final triangle count (after every refinement of the plan stage) with the U-turn
splits in brackets, and the median compile CPU seconds per tree (process time: on a shared
machine wall time mostly measures the other processes).  The baseline must have this tree's
module layout (``tlmpc.base``, ``tlmpc.pipeline.stages``); BASELINE_ROOT ``.`` measures this
tree alone (one run of its own is the quickest check of the triangle counts).
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

#: The same strip on the coarse mesh: one triangle wide, so the plan must turn around in it.
DEAD_END_COARSE = DEAD_END.replace(
    "name: dead-end\n", "name: dead-end-coarse\noptions: {min_angle: null, goal_depth: 0}\n"
)

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
        mesh = result.compilation.get(ABSTRACTION)
        triangles = f"{mesh.num_triangles} ({mesh.stats.get('split_for_u_turns', 0)})"
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
    (scratch / "dead-end-coarse.yaml").write_text(DEAD_END_COARSE)
    missions = [str(p) for p in sorted((ROOT / "specs").glob("*.yaml"))]
    missions += [str(scratch / "dead-end.yaml"), str(scratch / "dead-end-coarse.yaml")]
    trees = {"baseline": args.baseline.resolve(), "this tree": ROOT}
    runs: dict[str, list[dict[str, list[object]]]] = {name: [] for name in trees}
    for _ in range(args.repeats):
        for name, root in trees.items():
            runs[name].append(_run(root, missions))
    print(
        "| mission | triangles (U-turn splits), baseline | triangles (U-turn splits), this tree "
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
