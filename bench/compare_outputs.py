"""Artifacts byte for byte, before and after: ``tlmpc compile`` of each mission with two trees.

``python bench/compare_outputs.py --baseline DIR [--grids 100k,1M] [MISSION ...]`` compiles
every ``specs/`` mission (the reactive ones too; or the missions given) and the grid maps
named by ``--grids`` with this tree and with the baseline tree, each in a fresh interpreter,
and compares every file of the two output folders with the timings masked (the
``"...seconds": number`` fields).  It prints one line per mission and exits 1 when any file
differs or exists on one side only.  This is the check that a change meant to make the
compile faster changed no result.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench.bench_stages import _environment, workloads_of  # noqa: E402

#: A timing in a JSON artifact: the stage reports' and the summary's seconds.
TIMING = re.compile(rb'("[a-z_]*seconds"\s*:\s*)-?[0-9.]+(?:e[-+]?[0-9]+)?')


def _compile(tree: Path, mission: Path, out: Path) -> int:
    done = subprocess.run(
        [sys.executable, "-m", "tlmpc", "compile", str(mission), "-o", str(out), "-q"],
        capture_output=True,
        env=_environment(tree),
        cwd=tempfile.gettempdir(),
        check=False,
    )
    (out.parent / f"{out.name}.stderr").write_bytes(done.stderr)
    return done.returncode


def _masked(path: Path) -> bytes:
    return TIMING.sub(rb"\1T", path.read_bytes())


def differences(left: Path, right: Path) -> list[str]:
    """Names of the files that differ (timings masked) or exist in one folder only."""
    names = {p.name for p in left.iterdir()} | {p.name for p in right.iterdir()}
    found = []
    for name in sorted(names):
        a, b = left / name, right / name
        if not a.exists() or not b.exists():
            found.append(f"{name} (one side only)")
        elif a.is_file() and _masked(a) != _masked(b):
            found.append(name)
    return found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python bench/compare_outputs.py", description=__doc__)
    parser.add_argument("--baseline", type=Path, required=True, help="the tree to compare with")
    parser.add_argument("--grids", default="", help="grid maps too, e.g. 100k,1M")
    parser.add_argument("missions", nargs="*", type=Path)
    args = parser.parse_args(argv)
    missions = list(args.missions) or sorted(
        [*ROOT.glob("specs/*.yaml"), *ROOT.glob("specs/reactive/*.yaml")]
    )
    failed = 0
    with tempfile.TemporaryDirectory(prefix="tlmpc-compare-") as tmp:
        grids = workloads_of(args.grids, Path(tmp))
        grids.pop("example8")
        for number, mission in enumerate([*missions, *grids.values()]):
            outs = []
            codes = []
            for side, tree in (("new", ROOT), ("old", args.baseline.resolve())):
                out = Path(tmp) / f"{number}-{side}"
                codes.append(_compile(tree, mission, out))
                outs.append(out)
            if codes[0] != codes[1]:
                print(f"DIFFERS {mission.name}: exit {codes[0]} against {codes[1]}")
                failed += 1
                continue
            if not outs[0].exists() and not outs[1].exists():
                print(f"same    {mission.name}: exit {codes[0]}, no artifacts")
                continue
            found = differences(outs[0], outs[1])
            files = len(list(outs[0].iterdir()))
            if found:
                failed += 1
                print(f"DIFFERS {mission.name}: " + ", ".join(found))
            else:
                print(f"same    {mission.name}: exit {codes[0]}, {files} files")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
