"""Sensors and actions never merge with the game's own variables.

The game names the robot's motion ``face``, ``goal`` and ``moved`` and each monitor's memory
``task_monitor_N`` / ``assumed_monitor_N``; sensors and actions are identifiers in the same
name space.  A sensor called ``moved`` once became the motion's ``moved`` (the environment
could no longer raise it, and ``G !moved`` was called realizable), and an action called like
a monitor crashed the solver.
"""

from __future__ import annotations

import dataclasses

import pytest

from tlmpc.abstraction import build_abstraction
from tlmpc.base.errors import InvalidInputError
from tlmpc.mission import load_mission_text
from tlmpc.mission.model import Reactive, Sensor
from tlmpc.reactive.synthesize import mission_game, synthesize

MISSION = """\
version: 1
workspace: {{boundary: {{rect: [0, 0, 3, 2]}}}}
regions:
  r0: {{rect: [0, 0, 1, 2]}}
  r1: {{rect: [2, 0, 3, 2]}}
sensors: {{{sensors}}}
actions: {{{actions}}}
assumptions: ["G(s -> F !s)"]
robot: {{start: [1.5, 1]}}
options: {{min_angle: null}}
task:
  - visit r0 infinitely often
  - if you sense s then visit r1
ltl: "{ltl}"
"""


def _text(sensors: str = "s: null", actions: str = "beep: null", ltl: str = "true") -> str:
    return MISSION.format(sensors=sensors, actions=actions, ltl=ltl)


@pytest.mark.parametrize("name", ["face", "goal", "moved"])
@pytest.mark.parametrize("kind", ["sensors", "actions"])
def test_a_motion_name_is_refused_at_its_key(kind: str, name: str) -> None:
    text = (
        _text(sensors=f"s: null, {name}: null")
        if kind == "sensors"
        else _text(actions=f"{name}: null")
    )
    with pytest.raises(InvalidInputError) as caught:
        load_mission_text(text, "m.yaml")
    (found,) = caught.value.diagnostics
    assert found.code == "S013"
    assert (found.line, found.col) == (
        6 if kind == "sensors" else 7,
        text.splitlines()[5 if kind == "sensors" else 6].index(name) + 1,
    )
    assert found.hint


def test_a_sensor_named_moved_cannot_hide_behind_the_motion() -> None:
    """The environment may raise any sensor at any step, so ``G !alarm`` is unrealizable;
    renamed ``moved``, the sensor must be refused rather than read as the motion's flag."""
    with pytest.raises(InvalidInputError):
        load_mission_text(_text(sensors="s: null, moved: null", ltl="G !moved"), "m.yaml")
    mission = load_mission_text(_text(sensors="s: null, alarm: null", ltl="G !alarm"), "m.yaml")
    assert not synthesize(mission, build_abstraction(mission)).realizable


def test_an_edited_mission_json_with_a_motion_name_is_refused() -> None:
    mission = load_mission_text(_text(), "m.yaml")
    assert mission.reactive is not None
    edited = dataclasses.replace(
        mission,
        reactive=dataclasses.replace(
            mission.reactive, sensors=(*mission.reactive.sensors, Sensor(name="goal"))
        ),
    )
    with pytest.raises(InvalidInputError) as caught:
        mission_game(edited, build_abstraction(edited))
    assert [d.code for d in caught.value.diagnostics] == ["S013"]
    assert Reactive(actions=("face", "beep")).motion_clashes() == ("face",)


@pytest.mark.parametrize("name", ["assumed_monitor_0", "task_monitor_2", "task_monitor_2_"])
@pytest.mark.parametrize("kind", ["sensors", "actions"])
def test_a_name_like_a_monitor_is_an_ordinary_name(kind: str, name: str) -> None:
    """Renaming a sensor or an action changes neither the verdict nor the strategy's size."""

    def solved(other: str) -> tuple[bool, int, int]:
        text = (
            _text(sensors=f"s: null, {other}: null", ltl=f"G({other} -> F r1)")
            if kind == "sensors"
            else _text(actions=f"{other}: null", ltl=f"G(s -> {other})")
        )
        mission = load_mission_text(text, "m.yaml")
        found = synthesize(mission, build_abstraction(mission))
        names = [v.name for v in found.game.spec.variables]
        assert len(names) == len(set(names)), names
        assert found.size is not None
        return found.realizable, found.size.nodes, found.size.transitions

    assert solved(name) == solved("other_name")
