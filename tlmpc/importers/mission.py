"""An imported map as a mission document (explicit polygons), ready for ``tlmpc check``."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

import shapely
import yaml
from shapely.geometry import Polygon, box
from shapely.ops import polylabel

from tlmpc.base.errors import UsageError, error
from tlmpc.importers.maps import ImportedMap, Point, Ring
from tlmpc.importers.polygonize import polygons

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_KEYWORDS = {"F", "G", "X", "N", "U", "R", "W", "M", "V", "true", "false"}


def _points(ring: Ring) -> list[list[float]]:
    return [[x, y] for x, y in ring]


def _free_workspace(imported: ImportedMap) -> Any:
    pieces = [Polygon(imported.boundary, imported.holes)]
    pieces += [Polygon(outer, inner) for outer, inner in imported.components]
    return shapely.union_all(pieces)


def default_start(imported: ImportedMap) -> Point:
    """The free point farthest from obstacles and keepout regions (pole of inaccessibility)."""
    free: Any = Polygon(imported.boundary, imported.holes)
    keepout = [Polygon(imported.regions[n]) for n in imported.groups.get("keepout", ())]
    if keepout:
        free = free.difference(shapely.union_all(keepout))
    pieces = polygons(free) or [Polygon(imported.boundary, imported.holes)]
    largest = max(pieces, key=lambda p: p.area)
    point = polylabel(largest, tolerance=imported.resolution)
    return float(point.x), float(point.y)


def _clip_rect(
    imported: ImportedMap, name: str, rect: tuple[float, float, float, float]
) -> list[list[float]]:
    if not _NAME.match(name) or name in _KEYWORDS or name in imported.regions:
        raise UsageError(
            error(
                "M017",
                f"--region {name}: not a usable region name",
                hint="an identifier, not an LTL keyword and not an imported region's name",
            )
        )
    x0, y0, x1, y1 = rect
    if not (x0 < x1 and y0 < y1 and all(math.isfinite(v) for v in rect)):
        raise UsageError(error("M017", f"--region {name}: need XMIN < XMAX and YMIN < YMAX"))
    free = Polygon(imported.boundary, imported.holes)
    outer = Polygon(imported.boundary)
    minx, miny, maxx, maxy = outer.bounds
    # A hair inside the boundary (a hundred-billionth of the coordinates' size): above rounding,
    # so the boundary covers the region exactly, and far below the triangulation's snap grid.
    size = max(abs(minx), abs(miny), abs(maxx), abs(maxy), maxx - minx, maxy - miny)
    inside = outer.buffer(-1e-11 * size, join_style="mitre")
    clipped = polygons(box(x0, y0, x1, y1).intersection(inside))
    usable = [p for p in clipped if p.intersection(free).area > 0]
    if not usable:
        raise UsageError(
            error("M017", f"--region {name} has no free space in the imported workspace")
        )
    largest = max(usable, key=lambda p: p.area)
    return _points(tuple(largest.exterior.coords)[:-1])


def mission_document(
    imported: ImportedMap,
    *,
    name: str,
    start: Point | None = None,
    task: Sequence[str] | None = None,
    ltl: str | None = None,
    max_speed: float = 1.0,
    rects: Mapping[str, tuple[float, float, float, float]] | None = None,
) -> dict[str, Any]:
    """A ``version: 1`` mission with the imported workspace, regions and groups.

    Refuses (M018) what ``tlmpc check`` would reject in the written mission: a start that is
    not a finite point of the free workspace, a speed that is not a positive finite number."""
    if not (math.isfinite(max_speed) and max_speed > 0):
        raise UsageError(
            error(
                "M018",
                f"--max-speed must be a positive finite number, got {max_speed:g}",
                hint="the robot's speed bound in map units per second, e.g. --max-speed 0.5",
            )
        )
    if start is not None:
        free = _free_workspace(imported)
        if not all(math.isfinite(v) for v in start) or not free.covers(
            shapely.Point(start[0], start[1])
        ):
            raise UsageError(
                error(
                    "M018",
                    f"--start {start[0]:g} {start[1]:g} is not a point of the free workspace",
                    hint="choose a free point of the map, or leave --start out for the point "
                    "farthest from obstacles",
                    file=imported.source,
                )
            )
    regions: dict[str, Any] = {n: _points(r) for n, r in imported.regions.items()}
    for region, rect in (rects or {}).items():
        regions[region] = _clip_rect(imported, region, rect)
    if not regions:
        raise UsageError(
            error(
                "M016",
                "the mission would have no regions",
                hint="give --keepout or --speed masks, or --region NAME XMIN YMIN XMAX YMAX",
                file=imported.source,
            )
        )
    phrases = list(task or [])
    if not phrases and not ltl:
        if "keepout" not in imported.groups:
            raise UsageError(
                error(
                    "M016",
                    "the mission would have no task",
                    hint="give --task PHRASE or --ltl FORMULA (without a keepout mask there "
                    "is no default task)",
                    file=imported.source,
                )
            )
        phrases = ["avoid keepout"]
    document: dict[str, Any] = {
        "version": 1,
        "name": name,
        "workspace": {
            "boundary": _points(imported.boundary),
            "holes": [_points(h) for h in imported.holes],
            **(
                {
                    "components": [
                        {"boundary": _points(outer), "holes": [_points(h) for h in inner]}
                        for outer, inner in imported.components
                    ]
                }
                if imported.components
                else {}
            ),
        },
        "regions": regions,
    }
    if imported.groups:
        document["groups"] = {g: list(m) for g, m in imported.groups.items()}
    document["robot"] = {
        "start": list(start if start is not None else default_start(imported)),
        "max_speed": max_speed,
    }
    if phrases:
        document["task"] = phrases
    if ltl:
        document["ltl"] = ltl
    return document


def mission_yaml(document: Mapping[str, Any]) -> str:
    """The mission as YAML, points in flow style (``[x, y]``), floats exact (repr)."""
    header = (
        "# written by `tlmpc import-map`: the workspace is the free space of an occupancy-grid\n"
        "# map (configuration space when a radius was given); see docs/robot-data.md\n"
    )
    return header + yaml.safe_dump(
        dict(document), sort_keys=False, default_flow_style=None, width=100
    )
