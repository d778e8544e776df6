"""Mutation testing of tlmpc's critical lines: each mutant must make the test suite fail.

Usage::

    python tools/mutate.py                 # every mutant in tools/mutants.toml
    python tools/mutate.py --only verify   # mutants whose name contains "verify"
    python tools/mutate.py --list

A mutant names a file, an exact piece of source that occurs there exactly once, its
replacement, and the tests that must catch it.  Each mutant is applied to a fresh copy of the
repository's tracked files in a temporary directory (the working tree is never modified, so an
interrupted run leaves nothing behind), and the named tests run there with that copy first on
the import path.  A mutant is *killed* when the tests fail; one that survives, or whose source
piece is no longer found, makes the script exit 1.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_LIST = ROOT / "tools" / "mutants.toml"


@dataclass(frozen=True)
class Mutant:
    """One deliberate bug: ``find`` replaced by ``replace`` in ``file``."""

    name: str
    file: str
    find: str
    replace: str
    tests: tuple[str, ...]


@dataclass(frozen=True)
class Outcome:
    mutant: Mutant
    status: str  # "killed", "SURVIVED", "STALE" (source piece not found once)
    seconds: float
    detail: str = ""


def load_mutants(path: Path) -> list[Mutant]:
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    return [
        Mutant(
            name=entry["name"],
            file=entry["file"],
            find=entry["find"],
            replace=entry["replace"],
            tests=tuple(entry["tests"]),
        )
        for entry in data["mutant"]
    ]


def tracked_files() -> list[str]:
    listed = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True
    ).stdout.decode()
    return [name for name in listed.split("\0") if name]


def copy_tree(files: list[str], target: Path) -> None:
    for name in files:
        source = ROOT / name
        if not source.is_file():  # deleted in the working tree, not yet committed
            continue
        destination = target / name
        destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, destination)


def run_mutant(mutant: Mutant, files: list[str], timeout: float) -> Outcome:
    started = time.perf_counter()
    source = (ROOT / mutant.file).read_text(encoding="utf-8")
    if source.count(mutant.find) != 1:
        return Outcome(
            mutant, "STALE", 0.0, f"found {source.count(mutant.find)} times in {mutant.file}"
        )
    with tempfile.TemporaryDirectory(prefix="tlmpc-mutant-") as scratch:
        copy = Path(scratch)
        copy_tree(files, copy)
        (copy / mutant.file).write_text(source.replace(mutant.find, mutant.replace), "utf-8")
        env = dict(os.environ, PYTHONPATH=str(copy), PYTHONDONTWRITEBYTECODE="1")
        # The copy has no ``../shared`` beside it: its tests read the repository's (else the
        # tests that need the benchmark suites or the robot data skip, and a mutant only
        # they catch survives).
        shared = ROOT.parent / "shared"
        env.setdefault("TLMPC_SHARED_BENCHMARKS", str(shared / "benchmarks"))
        env.setdefault("TLMPC_SHARED_DATA", str(shared / "data"))
        command = [
            sys.executable, "-m", "pytest", "-x", "-q", "-n", "0",
            "-p", "no:cacheprovider", *mutant.tests,
        ]  # fmt: skip
        try:
            done = subprocess.run(
                command, cwd=copy, env=env, capture_output=True, text=True, timeout=timeout
            )
        except subprocess.TimeoutExpired:
            # A mutant that makes the tests hang is caught too (an infinite loop is a bug).
            return Outcome(mutant, "killed", time.perf_counter() - started, "timed out")
    seconds = time.perf_counter() - started
    lines = [line for line in done.stdout.splitlines() if line.strip()]
    detail = lines[-1] if lines else done.stderr.strip()[-200:]
    # The test that killed the mutant (pytest's short summary), so a report can name it.
    killer = next((line for line in lines if line.startswith("FAILED ")), None)
    if killer is not None:
        detail = f"{killer.removeprefix('FAILED ').split(' - ')[0]}; {detail}"
    if done.returncode == 1:
        return Outcome(mutant, "killed", seconds, detail)
    if done.returncode == 0:
        return Outcome(mutant, "SURVIVED", seconds, detail)
    # 2-5: interrupted, internal error, usage error, nothing collected: not a kill by a test.
    return Outcome(mutant, "ERROR", seconds, f"pytest exit {done.returncode}: {detail}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mutants", type=Path, default=DEFAULT_LIST)
    parser.add_argument("--only", help="run the mutants whose name contains this text")
    parser.add_argument("--list", action="store_true", help="list the mutants and stop")
    parser.add_argument("--timeout", type=float, default=900.0, help="seconds per mutant")
    args = parser.parse_args(argv)

    mutants = load_mutants(args.mutants)
    if args.only:
        mutants = [m for m in mutants if args.only in m.name]
    if args.list:
        for mutant in mutants:
            print(f"{mutant.name}  ({mutant.file})")
        return 0
    files = tracked_files()
    outcomes = []
    for mutant in mutants:
        outcome = run_mutant(mutant, files, args.timeout)
        outcomes.append(outcome)
        print(f"{outcome.status:<8} {outcome.seconds:6.1f} s  {mutant.name}  [{outcome.detail}]")
        sys.stdout.flush()
    bad = [o for o in outcomes if o.status != "killed"]
    print(f"\n{len(outcomes) - len(bad)} of {len(outcomes)} mutants killed")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
