"""Regions the assumptions name keep their true shape in a reactive mission's mesh.

The assumptions are the environment's promise about where the robot truly is.  A goal's core
(or an avoided region's grown shape) in their place makes the game's promise another one:
an environment that keeps the real promise could then break the game's (the strategy has no
answer, the robot stops), and the simulator's environments, keeping the game's, could break
the real one.  Checked against the mission's own rectangles (shapely), not the mesh's labels:

* every triangle lies inside or outside each region an assumption names, and is labelled so;
* a robot whose door sensor fires exactly while it is in the lab (by the rectangle) keeps
  going and meets its task;
* runs against the simulator's random and adversarial environments keep every assumption on
  the word read off the true regions (tests/oracles/reactive_runs.py, Spot).
"""

from __future__ import annotations

from typing import Any

import pytest
import shapely

pytest.importorskip("spot")

from reactive_runs import check_run, word

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.layout import planning_layout
from tlmpc.mission.body import requested_margin
from tlmpc.mission.load import load_mission_text
from tlmpc.mission.model import Mission
from tlmpc.reactive.synthesize import strategy_to_json, synthesize
from tlmpc.runtime.environments import AdversarialEnvironment, RandomEnvironment, time_scale
from tlmpc.runtime.reactive import ReactiveExecutor
from tlmpc.runtime.reactive_loop import run_reactive
from tlmpc.runtime.strategy_machine import StrategyMachine

LAB = (6.0, 2.0, 8.0, 4.0)

# the door sensor can fire only while the robot is in the lab, which it must visit: a goal
# (positive in the task) that the assumption names positively as well
DOOR = f"""\
version: 1
workspace:
  boundary: {{rect: [0, 0, 10, 6]}}
regions:
  dock: {{rect: [0.5, 0.5, 2.5, 2.5]}}
  lab: {{rect: {list(LAB)}}}
sensors:
  door: null
assumptions:
  - "G(!lab -> !door)"
robot: {{start: [1.5, 1.5], max_speed: 1.0}}
task:
  - visit lab infinitely often
  - visit dock infinitely often
"""

# the sensor never fires while the robot is in r1, which it must visit
QUIET = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 6]}
  holes: [{rect: [8.5, 0.5, 9.5, 1.5]}]
regions:
  r0: {rect: [2.3, 2.3, 3.7, 3.7]}
  r1: {rect: [6.3, 2.3, 7.7, 3.7]}
sensors:
  s1: null
assumptions:
  - "G(r1 -> !s1)"
robot: {start: [7.0, 5.0], max_speed: 1.0}
task:
  - visit r1 infinitely often
  - visit r0 infinitely often
"""


def _abstraction(mission: Mission) -> Any:
    """The mesh `tlmpc compile` triangulates (its abstraction stage's layout)."""
    return build_abstraction(mission, planning_layout(mission, requested_margin(mission)))


def _compiled(text: str, name: str) -> tuple[Mission, Any, dict[str, Any]]:
    mission = load_mission_text(text, f"{name}.yaml")
    abstraction = _abstraction(mission)
    synthesis = synthesize(mission, abstraction)
    assert synthesis.realizable
    return mission, abstraction, strategy_to_json(synthesis)


def _executor(found: tuple[Mission, Any, dict[str, Any]]) -> ReactiveExecutor:
    mission, abstraction, strategy = found
    assert mission.reactive is not None
    machine = StrategyMachine.of_json(
        strategy, mission.reactive.sensor_names, mission.reactive.actions, "strategy.json"
    )
    return ReactiveExecutor(mission=mission, abstraction=abstraction, machine=machine)


@pytest.mark.parametrize(("text", "region"), [(DOOR, "lab"), (QUIET, "r1")])
def test_triangles_are_labelled_by_the_true_region(text: str, region: str) -> None:
    mission = load_mission_text(text, "m.yaml")
    abstraction = _abstraction(mission)
    shape = shapely.Polygon(next(r.polygon for r in mission.regions if r.name == region))
    for index, corners in enumerate(abstraction.triangles):
        triangle = shapely.Polygon([abstraction.vertices[c] for c in corners])
        overlap = triangle.intersection(shape).area / triangle.area
        assert overlap < 1e-9 or overlap > 1 - 1e-9, f"triangle {index} straddles {region}"
        labelled = region in abstraction.letters[abstraction.letter_of[index]]
        assert labelled == (overlap > 0.5), f"triangle {index} is labelled wrongly"


def test_a_sensor_that_keeps_the_true_assumption_never_stops_the_robot() -> None:
    executor = _executor(_compiled(DOOR, "door"))
    lab = shapely.box(*LAB)
    x, y, t, dt = 1.5, 1.5, 0.0, 0.01
    entries = {"lab": 0, "dock": 0}
    inside = {"lab": False, "dock": False}
    dock = shapely.box(0.5, 0.5, 2.5, 2.5)
    while t < 60.0:
        here = shapely.Point(x, y)
        door = lab.contains(here)  # G(!lab -> !door), exactly, by the rectangle
        vx, vy = executor.command((x, y), t, {"door": door})
        assert executor.status == "following", f"stopped at t={t:.2f} in ({x:.3f}, {y:.3f})"
        for name, shape in (("lab", lab), ("dock", dock)):
            now = shape.contains(here)
            entries[name] += now and not inside[name]
            inside[name] = now
        x, y, t = x + vx * dt, y + vy * dt, t + dt
    assert entries["lab"] >= 2
    assert entries["dock"] >= 2


@pytest.mark.parametrize("kind", ["random", "adversarial"])
@pytest.mark.parametrize("seed", [0, 1])
def test_simulated_environments_keep_the_true_assumption(kind: str, seed: int) -> None:
    found = _compiled(QUIET, "quiet")
    executor = _executor(found)
    sensors = executor.machine.sensors
    scale = time_scale(executor)
    environment = (
        RandomEnvironment(sensors, seed, scale)
        if kind == "random"
        else AdversarialEnvironment(sensors, seed, scale)
    )
    run = run_reactive(executor, environment, events=60)
    check_run(run.trace, found[2])  # every assumption kept on the true regions' word
    assert sum("r1" in letter for letter in word(run.trace)) >= 2
