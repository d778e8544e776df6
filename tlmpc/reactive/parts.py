"""The parts of a reactive mission, each with the player it binds."""

from __future__ import annotations

from tlmpc.mission.model import Mission, TaskPart
from tlmpc.mission.parts import task_parts
from tlmpc.reactive.fragment import Owner


def mission_parts(mission: Mission) -> list[tuple[TaskPart, Owner]]:
    """Every assumption (the environment's) and every task part (the robot's), in file order."""
    assert mission.reactive is not None
    env: list[tuple[TaskPart, Owner]] = [(p, "env") for p in mission.reactive.assumptions]
    return env + [(p, "sys") for p in task_parts(mission)]
