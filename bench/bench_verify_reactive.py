"""Reactive log verification: a 1 h CSV log at 10 Hz with and without three sensor columns.

The robot patrols four rooms of a corridor map (a square lap every 40 s); three sensors
(``alarm``, ``door``, ``person``) change at random every half a minute or so, sampled on every
row as true/false.  Timed: reading the log against the mission and verifying it
(``read_trace`` + ``verify_trace``), the same log and map without the sensors and with the
task's region part only, and the reactive run when the robot breaks its guarantee (the
bisection for the breaking time then runs).
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

HZ = 10.0
HOUR = 3600.0
SENSORS = ("alarm", "door", "person")
LAP = [(1.0, 1.0), (9.0, 1.0), (9.0, 9.0), (1.0, 9.0)]
LAP_SECONDS = 40.0

MISSION = """\
version: 1
workspace: {{boundary: {{rect: [0, 0, 10, 10]}}}}
regions:
  r1: {{rect: [0, 0, 2, 2]}}
  r2: {{rect: [8, 0, 10, 2]}}
  r3: {{rect: [8, 8, 10, 10]}}
  r4: {{rect: [0, 8, 2, 10]}}
  lab: {{rect: [4, 4, 6, 6]}}
{reactive}robot: {{start: [1, 1], max_speed: 2}}
ltl: "{ltl}"
"""

REGION_TASK = "G F r1 & G F r3 & G !lab"
REACTIVE = """\
sensors: {alarm: null, door: null, person: null}
assumptions: ["G F !alarm", "G F !person"]
"""
REACTIVE_TASK = REGION_TASK + " & G(alarm -> F r1) & G(person -> !lab) & G(door -> F r2)"


def _positions(times: np.ndarray) -> np.ndarray:
    phase = (times % LAP_SECONDS) / (LAP_SECONDS / 4)
    side = phase.astype(int) % 4
    along = phase - np.floor(phase)
    corners = np.asarray(LAP)
    start, end = corners[side], corners[(side + 1) % 4]
    positions: np.ndarray = start + along[:, None] * (end - start)
    return positions


def write_log(path: Path, *, sensors: bool, broken_at: float | None = None) -> None:
    """The 1 h log; ``broken_at``: the robot cuts through the lab once then (at x=5)."""
    times = np.arange(0.0, HOUR, 1.0 / HZ)
    positions = _positions(times)
    if broken_at is not None:
        near = np.abs(times - broken_at) < 1.0
        positions[near] = [5.0, 5.0]
    rng = np.random.default_rng(0)
    columns = [times, positions[:, 0], positions[:, 1]]
    header = "t,x,y"
    if sensors:
        for name in SENSORS:
            flips = np.sort(rng.uniform(0.0, HOUR, size=int(HOUR / 30)))
            value = (np.searchsorted(flips, times, side="right") % 2).astype(float)
            if name == "person" and broken_at is not None:
                value[np.abs(times - broken_at) < 2.0] = 1.0
            columns.append(value)
            header += f",{name}"
    np.savetxt(
        path, np.column_stack(columns), delimiter=",", header=header, comments="", fmt="%.6g"
    )


def _timed(log: Path, mission: Path, repeats: int) -> tuple[float, Any]:
    from tlmpc.verify import read_trace, verify_trace

    spent = []
    verdict = None
    for _ in range(repeats):
        start = time.perf_counter()
        verdict = verify_trace(read_trace(log, mission))
        spent.append(time.perf_counter() - start)
    return statistics.median(spent), verdict


def run(repeats: int = 3) -> list[dict[str, Any]]:
    """Median wall seconds of each case."""
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        base = Path(folder)
        cases = [
            ("regions only", False, "", REGION_TASK, None),
            ("3 sensors, 2 assumptions", True, REACTIVE, REACTIVE_TASK, None),
            ("3 sensors, guarantee broken", True, REACTIVE, REACTIVE_TASK, 1800.0),
        ]
        for name, sensors, reactive, ltl, broken in cases:
            log = base / f"{len(rows)}.csv"
            mission = base / f"{len(rows)}.yaml"
            write_log(log, sensors=sensors, broken_at=broken)
            mission.write_text(MISSION.format(reactive=reactive, ltl=ltl))
            seconds, verdict = _timed(log, mission, repeats)
            judged = verdict.reactive
            rows.append(
                {
                    "case": name,
                    "samples": verdict.stats["samples"],
                    "pieces": verdict.stats["raw_pieces"],
                    "verdict": verdict.outcome,
                    "blame": judged.blame if judged else "-",
                    "median_s": round(seconds, 3),
                }
            )
    return rows


if __name__ == "__main__":
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from bench.tables import markdown_table

    print(markdown_table(run()))
