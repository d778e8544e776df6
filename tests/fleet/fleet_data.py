"""Generated fleets with violations planted at known times and places, and their oracle.

Every log drives a robot at constant speed along one horizontal line ``y = y0`` from
``x0`` to ``x1`` through a rectangular workspace with a rectangular ``lake`` and ``goal``,
sampled every ``dt`` seconds from ``t_start``.  The expected verdict and the first violation
follow from the line alone (where it meets the lake's left edge: ``t = (LAKE[0] - x0) / v``),
not from the verifier.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

WORKSPACE = (0.0, 0.0, 20.0, 10.0)
LAKE = (8.0, 3.0, 12.0, 7.0)
GOAL = (16.0, 6.0, 19.0, 9.0)

AVOID_MISSION = f"""\
version: 1
name: fleet-avoid
workspace:
  boundary: {{rect: {list(WORKSPACE)}}}
regions:
  lake: {{rect: {list(LAKE)}}}
  goal: {{rect: {list(GOAL)}}}
robot: {{start: [1.0, 1.0], max_speed: 2.0}}
task:
  - avoid lake
  - visit goal
"""

REACH_MISSION = AVOID_MISSION.replace("fleet-avoid", "fleet-reach").replace("  - avoid lake\n", "")


@dataclass(frozen=True)
class Planted:
    """One generated log and what the oracle expects of it."""

    path: Path
    task: str  # "avoid" (visit goal, avoid lake) or "reach" (visit goal)
    verdict: str
    first_t: float | None  # seconds from the log's start
    first_x: float | None
    first_y: float | None
    conjunct: str | None


def _expected(task: str, y0: float, x0: float, x1: float, speed: float) -> Planted:
    crosses_lake = LAKE[1] < y0 < LAKE[3] and x0 < LAKE[0] < x1
    reaches_goal = GOAL[1] < y0 < GOAL[3] and x0 < GOAL[2] and x1 > GOAL[0]
    if task == "avoid" and crosses_lake:
        t = (LAKE[0] - x0) / speed
        return Planted(Path(), task, "violated", t, LAKE[0], y0, "G !lake")
    if task == "reach" and reaches_goal:
        return Planted(Path(), task, "satisfied", None, None, None, None)
    return Planted(Path(), task, "inconclusive", None, None, None, None)


def generate(folder: Path, count: int, seed: int = 0) -> list[Planted]:
    """``count`` logs under ``folder/robotR/DAY/``; each log's name says its task."""
    rng = np.random.default_rng(seed)
    found: list[Planted] = []
    for index in range(count):
        task = "avoid" if index % 3 else "reach"
        y0 = float(rng.choice([1.5, 4.0, 5.25, 6.5, 7.5, 8.25]))
        x0 = float(rng.uniform(0.5, 7.0))
        x1 = float(rng.uniform(13.0, 19.5))
        speed = float(rng.uniform(0.3, 1.5))
        dt = float(rng.choice([0.02, 0.1, 0.25]))
        start = float(rng.uniform(0.0, 1e5))
        steps = int((x1 - x0) / speed / dt)
        t = np.arange(steps + 1) * dt
        x = x0 + speed * t
        y = np.full_like(t, y0)
        robot, day = f"robot{index % 4}", f"2026-11-{1 + index % 3:02d}"
        path = folder / robot / day / f"{task}-{index:03d}.csv"
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "w", encoding="utf-8") as stream:
            stream.write("t,x,y\n")
            np.savetxt(stream, np.column_stack([start + t, x, y]), fmt="%.17g", delimiter=",")
        expected = _expected(task, y0, x0, float(x[-1]), speed)
        found.append(
            Planted(
                path,
                task,
                expected.verdict,
                expected.first_t,
                expected.first_x,
                expected.first_y,
                expected.conjunct,
            )
        )
    return found


def write_missions(folder: Path) -> Path:
    """The two missions and a mapping file choosing by the log's name; returns the mapping."""
    (folder / "avoid.yaml").write_text(AVOID_MISSION, encoding="utf-8")
    (folder / "reach.yaml").write_text(REACH_MISSION, encoding="utf-8")
    mapping = folder / "missions.yaml"
    mapping.write_text(
        "format: tlmpc.fleet-missions/1\n"
        "missions:\n"
        "  - {logs: 'reach-*.csv', mission: reach.yaml}\n"
        "  - {logs: '*/avoid-*.csv', mission: avoid.yaml}\n",
        encoding="utf-8",
    )
    return mapping
