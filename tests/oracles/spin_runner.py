"""Run SPIN on a model written by :func:`tlmpc.planning.export.to_promela` and read its trail.

SPIN is the independent oracle of the paper's route: ``spin -a`` generates ``pan.c``, ``gcc``
compiles it, ``./pan -a`` searches for a counterexample to ``!task`` (a plan), and ``spin -t``
replays the trail, whose ``tlmpc: t = N`` lines are the triangles entered.  With
``shortest=True`` pan is compiled with ``-DREACH`` and run with ``-i``, which makes the trail
of a *safety* violation (how SPIN's claim ends for co-safe tasks such as "visit a then b") the
shortest one; for acceptance cycles SPIN gives no such guarantee.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

_ENTERED = re.compile(r"^\s*tlmpc: t = (\d+)\s*$")
_ERRORS = re.compile(r"errors: (\d+)")


class SpinError(RuntimeError):
    """SPIN or gcc failed, ran out of a benchmark's time, or could not finish its search."""


@dataclass(frozen=True, slots=True, kw_only=True)
class SpinTrail:
    """What SPIN found on one model."""

    found: bool  # a counterexample to !task, i.e. a plan for the task
    entered: tuple[int, ...]  # triangles entered, in order (the start is not repeated)
    cycle_from: int | None  # entered[cycle_from:] is the accepting cycle; None: finite trail
    seconds: Mapping[str, float] = field(default_factory=dict)  # per phase

    @property
    def moves(self) -> int:
        """Moves of the whole trail (prefix and, for a lasso, one turn of the cycle)."""
        return len(self.entered)


def available() -> bool:
    """True when ``spin`` and ``gcc`` are on the PATH."""
    return shutil.which("spin") is not None and shutil.which("gcc") is not None


def run_command(command: list[str], cwd: Path, timeout: float | None) -> tuple[float, str]:
    """Run ``command``; on timeout kill its whole process group (gcc leaves cc1 behind).

    ``timeout`` is for the benchmarks only: a test passes None (SPIN's search is bounded by
    its depth bound, ``-m``; a verdict must never depend on the machine's load)."""
    started = time.perf_counter()
    process = subprocess.Popen(
        command,
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    try:
        output, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired as timed_out:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        raise SpinError(f"{command[0]} timed out after {timeout:g} s") from timed_out
    if process.returncode != 0 and command[0] != "./pan":
        raise SpinError(f"{' '.join(command)} failed:\n{output[-2000:]}")
    return time.perf_counter() - started, output


def parse_trail(replay: str) -> tuple[tuple[int, ...], int | None]:
    """The triangles entered and where the cycle starts, from ``spin -t`` output."""
    entered: list[int] = []
    cycle_from: int | None = None
    for line in replay.splitlines():
        if "START OF CYCLE" in line:
            cycle_from = len(entered)
        elif match := _ENTERED.match(line):
            entered.append(int(match.group(1)))
    return tuple(entered), cycle_from


def run_spin(
    model: Path, *, shortest: bool = False, timeout: float | None = None, max_depth: int = 1_000_000
) -> SpinTrail:
    """Generate, compile and search ``model`` (a ``.pml`` file) in its directory."""
    work = model.parent
    defines = ["-DNOREDUCE", *(["-DREACH"] if shortest else [])]
    seconds: dict[str, float] = {}
    seconds["spin -a"], _ = run_command(["spin", "-a", model.name], work, timeout)
    seconds["gcc"], _ = run_command(["gcc", "-O2", *defines, "-o", "pan", "pan.c"], work, timeout)
    search = ["./pan", "-a", f"-m{max_depth}", *(["-i"] if shortest else [])]
    seconds["pan"], output = run_command(search, work, timeout)
    errors = _ERRORS.search(output)
    if errors is None:
        raise SpinError(f"pan printed no result:\n{output[-2000:]}")
    if int(errors.group(1)) == 0:
        if "max search depth too small" in output:
            raise SpinError(f"pan stopped at its depth bound {max_depth}: no verdict")
        return SpinTrail(found=False, entered=(), cycle_from=None, seconds=seconds)
    seconds["spin -t"], replay = run_command(["spin", "-t", model.name], work, timeout)
    entered, cycle_from = parse_trail(replay)
    return SpinTrail(found=True, entered=entered, cycle_from=cycle_from, seconds=seconds)
