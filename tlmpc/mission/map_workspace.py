"""``workspace: {map: FILE.yaml, ...}``: a mission's workspace taken from an occupancy-grid map.

The map (and its optional ``keepout`` / ``speed`` masks) is read by :mod:`tlmpc.importers`,
only when a mission uses this form, so plain missions never load an image library.  Paths
are relative to the mission file.  Imported mask regions and groups join the mission's own.
"""

from __future__ import annotations

from pathlib import Path as FilePath
from typing import Any

from shapely.geometry import Polygon as ShapelyPolygon

from tlmpc.base.errors import Diagnostic, TlmpcError, error
from tlmpc.mission.geometry import check_shape
from tlmpc.mission.shapes import CheckedShape
from tlmpc.mission.yamlpos import PositionedDocument


def _resolve(mission_file: str, value: str) -> FilePath:
    path = FilePath(value)
    if path.is_absolute():
        return path
    return FilePath(mission_file).parent / path


def _has_body(robot: Any) -> bool:
    """True when the mission's robot (as written) has a body: a radius, an inflation, a
    footprint, or a unicycle's axle behind its reference point."""
    if not isinstance(robot, dict):
        return False
    sized = any(robot.get(key) for key in ("radius", "inflate", "footprint"))
    return bool(sized) or robot.get("model") == "unicycle"


def map_shapes(
    data: dict[str, Any], doc: PositionedDocument, file: str
) -> tuple[
    CheckedShape | None,
    list[CheckedShape],
    dict[str, CheckedShape],
    list[Diagnostic],
    list[tuple[CheckedShape, list[CheckedShape]]],
]:
    """The boundary, holes and regions (imported first, then the mission's own), and the
    further free components of the map, each with its holes."""
    from tlmpc.importers.maps import ImportSettings, import_map

    workspace: dict[str, Any] = data["workspace"]
    where = ("workspace", "map")
    line, col = doc.value_at(where)
    drawn = [k for k in ("boundary", "holes", "components") if k in workspace]
    if drawn:
        key = drawn[0]
        kline, kcol = doc.key_at(("workspace", key))
        return (
            None,
            [],
            {},
            [
                error(
                    "M014",
                    f"workspace.{key} cannot be combined with workspace.map",
                    hint="the map gives the boundary and holes; remove one of the two",
                    file=file,
                    line=kline,
                    col=kcol,
                )
            ],
            [],
        )
    start = data["robot"]["start"]
    settings = ImportSettings(
        # the robot's body is the planner's business (configuration space, with robot.radius
        # or its alias inflate): the mission keeps the map's obstacles as they are
        radius=0.0,
        tolerance=workspace.get("tolerance"),
        min_area=workspace.get("min_area"),
        start=(float(start[0]), float(start[1])),
        # a body can hit an obstacle of a few cells: none is dropped as a speck
        keep_obstacles=_has_body(data["robot"]),
    )
    masks = {
        key: _resolve(file, workspace[key]) for key in ("keepout", "speed") if key in workspace
    }
    try:
        imported = import_map(
            _resolve(file, workspace["map"]),
            settings,
            keepout=masks.get("keepout"),
            speed=masks.get("speed"),
        )
    except TlmpcError as exc:
        return (
            None,
            [],
            {},
            [
                error(
                    d.code,
                    f"{d.location()}: {d.message}" if d.file and d.file != file else d.message,
                    hint=d.hint,
                    file=file,
                    line=line,
                    col=col,
                    path="$.workspace.map",
                )
                for d in exc.diagnostics
            ],
            [],
        )
    problems: list[Diagnostic] = []

    def shape(points: tuple[tuple[float, float], ...]) -> CheckedShape:
        return CheckedShape(points=points, polygon=ShapelyPolygon(points), path=where)

    boundary = shape(imported.boundary)
    holes = [shape(h) for h in imported.holes]
    components = [(shape(outer), [shape(h) for h in inner]) for outer, inner in imported.components]
    regions = {name: shape(points) for name, points in imported.regions.items()}
    user_groups: dict[str, Any] = dict(data.get("groups") or {})
    for name in list(data["regions"]) + list(user_groups):
        if name in regions or name in imported.groups:
            kline, kcol = doc.key_at(
                ("regions", name) if name in data["regions"] else ("groups", name)
            )
            problems.append(
                error(
                    "M015",
                    f"{name!r} is also the name of a region or group imported from a mask",
                    hint="imported names are keepout, keepout_K, speed_V and speed_V_K; "
                    "rename yours",
                    file=file,
                    line=kline,
                    col=kcol,
                )
            )
    for name, value in data["regions"].items():
        checked, found = check_shape(
            value, ("regions", name), f"region {name!r}", file, doc.value_at
        )
        problems.extend(found)
        if checked is not None:
            regions[name] = checked
    if not problems:
        data["groups"] = {**{g: list(m) for g, m in imported.groups.items()}, **user_groups}
        # the rings may be this far from the cells: a body keeps that much more (body.py)
        workspace["tolerance"] = imported.tolerance
    return boundary, holes, regions, problems, components
