"""A reactive robot that starts on the boundary of faces chooses the face it enters first.

Under the right-continuous convention the label at t = 0 is the one of the triangle the robot
moves into first, and every triangle holding the start may be that one (docs/semantics.md,
"Starts on a boundary").  The game used to fix the face of the mesh's lowest-numbered start
triangle, so a start on the edge of r0 could make `avoid r0` (or `r0` at the start)
unrealizable.  Oracle: shapely says the start lies on r0's edge, so both faces are a step away.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
import shapely

from tlmpc.abstraction import build_abstraction
from tlmpc.cli import main
from tlmpc.mission import load_mission_text
from tlmpc.reactive.synthesize import synthesize

MISSION = """\
version: 1
workspace: {{boundary: {{rect: [0, 0, 3, 2]}}}}
regions:
  r0: {{rect: [0, 0, 1, 2]}}
  r1: {{rect: [2, 0, 3, 2]}}
sensors: {{s: null}}
actions: {{beep: null}}
robot: {{start: [1, 1]}}
options: {{min_angle: null}}
task:
  - if you sense s then do beep
{task}"""

START_ON_EDGE = bool(shapely.box(0, 0, 1, 2).boundary.contains(shapely.Point(1, 1)))


def realizable(task: list[str]) -> bool:
    text = MISSION.format(task="".join(f"  - {p}\n" for p in task))
    mission = load_mission_text(text, "m.yaml")
    return synthesize(mission, build_abstraction(mission)).realizable


@pytest.mark.parametrize(
    "first", [["avoid r0"], ["visit r1 infinitely often", "avoid r0", "visit r1"]]
)
def test_the_robot_may_leave_the_edge_into_free_space(first: list[str]) -> None:
    assert START_ON_EDGE
    assert realizable(first)


def test_the_robot_may_enter_r0_first() -> None:
    assert START_ON_EDGE
    assert realizable(["always stay in r0"])


def test_a_core_conflicts_whichever_face_comes_first() -> None:
    """`avoid r0` and `always stay in r0` conflict from both faces; each alone is met."""
    text = MISSION.format(task="  - avoid r0\n  - always stay in r0\n")
    mission = load_mission_text(text, "m.yaml")
    found = synthesize(mission, build_abstraction(mission))
    assert not found.realizable
    assert found.core is not None
    assert {p.text for p in found.core} == {"avoid r0", "always stay in r0"}
    assert realizable(["avoid r0"])
    assert realizable(["always stay in r0"])


def test_the_executor_enters_the_face_the_strategy_starts_in(tmp_path: Path) -> None:
    source = tmp_path / "m.yaml"
    source.write_text(MISSION.format(task="  - avoid r0\n"))
    out, trace = tmp_path / "out", tmp_path / "trace.json"
    err = io.StringIO()
    assert main(["compile", str(source), "-o", str(out), "-q"], err=err) == 0, err.getvalue()
    argv = ["simulate", str(out), "--sensors", "adversarial", "--events", "12", "-o", str(trace)]
    assert main(argv, out=io.StringIO(), err=err) == 0, err.getvalue()
    points = json.loads(trace.read_text())["points"]
    r0 = shapely.box(0, 0, 1, 2)
    assert all(not r0.contains(shapely.Point(x, y)) for _, x, y in points[1:])


PAIR = """\
version: 1
workspace: {boundary: {rect: [0, 0, 10, 6]}}
regions:
  r0: {rect: [1, 1, 3, 3]}
  r1: {rect: [3, 1, 5, 3]}
sensors: {s: null}
assumptions: ["G(s | r1)", "!s"]
robot: {start: [3, 2]}
options: {min_angle: null}
task:
  - when s, go to r1 and stay there while s
"""


def test_a_start_the_environment_can_keep_comes_before_a_vacuous_one(tmp_path: Path) -> None:
    """The assumptions put the robot in r1 at the start (`!s` and `G(s | r1)`): entering r0
    first wins only vacuously, with no start to run; entering r1 first is the strategy."""
    assert bool(shapely.box(1, 1, 3, 3).boundary.contains(shapely.Point(3, 2)))
    assert bool(shapely.box(3, 1, 5, 3).boundary.contains(shapely.Point(3, 2)))
    mission = load_mission_text(PAIR, "m.yaml")
    found = synthesize(mission, build_abstraction(mission))
    assert found.strategy is not None
    labels = found.game.faces.letters
    assert found.strategy.initial
    assert all("r1" in labels[found.strategy.states[n]["face"]] for n in found.strategy.initial)
    source = tmp_path / "m.yaml"
    source.write_text(PAIR)
    out = tmp_path / "out"
    err = io.StringIO()
    assert main(["compile", str(source), "-o", str(out), "-q"], err=err) == 0, err.getvalue()
    argv = ["simulate", str(out), "--sensors", "random", "--events", "8"]
    assert main(argv, out=io.StringIO(), err=err) == 0, err.getvalue()
