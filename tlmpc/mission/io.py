"""``mission.json`` (``tlmpc.mission/1``) read back into a :class:`Mission`."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from tlmpc.mission.model import (
    Component,
    Mission,
    Options,
    Polygon,
    Reactive,
    Region,
    Robot,
    Sensor,
    TaskPart,
    Workspace,
)


def _polygon(points: Sequence[Sequence[float]]) -> Polygon:
    return tuple((float(x), float(y)) for x, y in points)


def mission_from_json(document: Mapping[str, Any]) -> Mission:
    """Rebuild the :class:`Mission` written by :meth:`Mission.to_json`.

    The formula is parsed again from its text (positions then refer to ``mission.json``).
    """
    from tlmpc.ltl.parser import parse_ltl

    options = document["options"]
    robot = document["robot"]
    return Mission(
        name=document["name"],
        workspace=Workspace(
            boundary=_polygon(document["workspace"]["boundary"]),
            holes=tuple(_polygon(h) for h in document["workspace"]["holes"]),
            components=tuple(
                Component(
                    boundary=_polygon(c["boundary"]),
                    holes=tuple(_polygon(h) for h in c["holes"]),
                )
                for c in document["workspace"].get("components", ())
            ),
            map_tolerance=float(document["workspace"].get("map_tolerance", 0.0)),
        ),
        regions=tuple(
            Region(name=name, polygon=_polygon(points))
            for name, points in document["regions"].items()
        ),
        robot=Robot(
            start=_polygon([robot["start"]])[0],
            max_speed=float(robot["max_speed"]),
            disturbance=float(robot.get("disturbance", 0.0)),
            model=robot.get("model", "point"),
            offset=float(robot.get("offset", 0.0)),
            radius=float(robot.get("radius", 0.0)),
            footprint=_polygon(robot["footprint"]) if robot.get("footprint") else None,
        ),
        formula=parse_ltl(document["formula"], file="mission.json"),
        groups={name: tuple(members) for name, members in document["groups"].items()},
        task=tuple(document["task"]),
        ltl=document["ltl"],
        options=Options(
            min_angle=options["min_angle"],
            max_area=options["max_area"],
            cost=options["cost"],
            beta=float(options["beta"]),
            boundary=options["boundary"],
            margin=options.get("margin"),
            goal_depth=options.get("goal_depth"),
        ),
        source=document.get("source"),  # optional in the schema: the file, for diagnostics
        reactive=_reactive(document.get("reactive")),
    )


def _reactive(document: Mapping[str, Any] | None) -> Reactive | None:
    from tlmpc.ltl.parser import parse_ltl

    if document is None:
        return None
    return Reactive(
        sensors=tuple(
            Sensor(name=name, **binding) for name, binding in document["sensors"].items()
        ),
        actions=tuple(document["actions"]),
        assumptions=tuple(
            TaskPart(text=part["text"], formula=parse_ltl(part["formula"], file="mission.json"))
            for part in document["assumptions"]
        ),
    )
