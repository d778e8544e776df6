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


def region_error(flag: str, message: str, hint: str) -> UsageError:
    """M017 about a ``--region``, located at the flag as it was given (``flag``)."""
    return UsageError(error("M017", message, hint=hint, file=flag))


def _check_rect(
    imported: ImportedMap, name: str, rect: tuple[float, float, float, float], flag: str
) -> None:
    if not _NAME.match(name) or name in _KEYWORDS or name in imported.regions:
        raise region_error(
            flag,
            f"{name!r} is not a usable region name",
            "an identifier, not an LTL keyword and not an imported region's name",
        )
    x0, y0, x1, y1 = rect
    if not (x0 < x1 and y0 < y1 and all(math.isfinite(v) for v in rect)):
        raise region_error(
            flag,
            "need finite bounds with XMIN < XMAX and YMIN < YMAX",
            "--region NAME XMIN YMIN XMAX YMAX: the rectangle's lower-left and upper-right corners",
        )


def _nearest_on_segment(p: Point, a: Point, b: Point) -> tuple[float, float]:
    """The distance from ``p`` to segment ``ab`` and the parameter of the nearest point."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length2
    t = min(1.0, max(0.0, t))
    return math.hypot(a[0] + t * dx - p[0], a[1] + t * dy - p[1]), t


def snap_to_rings(
    point: Point, rings: list[list[Point]], tolerance: float
) -> tuple[Point, tuple[int, int] | None]:
    """``point`` moved onto the workspace rings it came from, when it lies within
    ``tolerance`` of them: onto the nearest ring vertex, else returned as it is together with
    ``(ring, index)``, the place to insert it into a ring edge (so the ring and the region
    share it exactly).  Far from every ring: unchanged, ``None``."""
    best_vertex: Point | None = None
    best = tolerance
    for ring in rings:
        for vertex in ring:
            distance = math.hypot(vertex[0] - point[0], vertex[1] - point[1])
            if distance <= best:
                best, best_vertex = distance, vertex
    if best_vertex is not None:
        return best_vertex, None
    best_edge: tuple[int, int] | None = None
    best = tolerance
    for r, ring in enumerate(rings):
        for i, a in enumerate(ring):
            distance, t = _nearest_on_segment(point, a, ring[(i + 1) % len(ring)])
            if distance <= best and 0.0 < t < 1.0:
                best, best_edge = distance, (r, i + 1)
    return point, best_edge


def _clip_rects(
    imported: ImportedMap,
    rects: Mapping[str, tuple[float, float, float, float]],
    flags: Mapping[str, str],
) -> tuple[Ring, tuple[Ring, ...], dict[str, list[list[float]]]]:
    """Each rectangle clipped to the workspace's outer boundary, and the boundary and holes
    noded with the clipped regions; a rectangle's problems are located at its flag in
    ``flags`` (else at ``--region NAME``).

    A clipped region's vertices on the boundary are the boundary's own: the boundary
    vertices it follows are copied exactly, and each point where a rectangle's edge crosses a
    boundary edge (computed, so a rounding error off that edge) is inserted into the boundary
    as a vertex that both rings share.  Any vertex within a billionth of the map's size of a
    workspace ring is snapped onto it this way.  Without this, a region edge a few 1e-11 m
    beside a wall leaves a sliver between them that the quality mesh refines into tens of
    thousands of triangles.
    """
    rings = [list(imported.boundary), *[list(h) for h in imported.holes]]
    outer = Polygon(imported.boundary)
    minx, miny, maxx, maxy = outer.bounds
    size = max(abs(minx), abs(miny), abs(maxx), abs(maxy), maxx - minx, maxy - miny)
    tolerance = 1e-9 * size
    regions: dict[str, list[list[float]]] = {}
    for name, rect in rects.items():
        flag = flags.get(name, f"--region {name}")
        _check_rect(imported, name, rect, flag)
        free = Polygon(rings[0], rings[1:])
        clipped = polygons(box(*rect).intersection(Polygon(rings[0])))
        usable = [p for p in clipped if p.intersection(free).area > 0]
        if not usable:
            raise region_error(
                flag,
                "the rectangle has no free space in the imported workspace",
                f"the workspace spans x {minx:g} to {maxx:g}, y {miny:g} to {maxy:g}; a "
                "region must overlap its free space",
            )
        largest = max(usable, key=lambda p: p.area)
        ring: list[Point] = []
        for x, y in list(largest.exterior.coords)[:-1]:
            point, insert = snap_to_rings((float(x), float(y)), rings, tolerance)
            if insert is not None:
                rings[insert[0]].insert(insert[1], point)
            if not ring or ring[-1] != point:
                ring.append(point)
        if len(ring) > 1 and ring[0] == ring[-1]:
            ring.pop()
        regions[name] = [[x, y] for x, y in ring]
    return tuple(rings[0]), tuple(tuple(h) for h in rings[1:]), regions


def mission_document(
    imported: ImportedMap,
    *,
    name: str,
    start: Point | None = None,
    task: Sequence[str] | None = None,
    ltl: str | None = None,
    max_speed: float = 1.0,
    rects: Mapping[str, tuple[float, float, float, float]] | None = None,
    flags: Mapping[str, str] | None = None,
) -> dict[str, Any]:
    """A ``version: 1`` mission with the imported workspace, regions and groups.

    ``rects`` are rectangular regions to add, each clipped to the workspace; ``flags`` says
    where each was given (its ``--region`` flag), where its problems (M017) are located.
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
    boundary, holes, clipped = _clip_rects(imported, rects or {}, flags or {})
    regions.update(clipped)
    phrases = list(task or [])
    if not phrases and not ltl and "keepout" in imported.groups:
        phrases = ["avoid keepout"]
    document: dict[str, Any] = {
        "version": 1,
        "name": name,
        "workspace": {
            "boundary": _points(boundary),
            "holes": [_points(h) for h in holes],
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
    }
    if regions:
        document["regions"] = regions
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


def unfinished(document: Mapping[str, Any]) -> list[str]:
    """What a mission still lacks before it can be checked: ``regions``, ``task``."""
    missing = [] if "regions" in document else ["regions"]
    if "task" not in document and "ltl" not in document:
        missing.append("task")
    return missing


def mission_yaml(document: Mapping[str, Any]) -> str:
    """The mission as YAML, points in flow style (``[x, y]``), floats exact (repr); a mission
    still without regions or a task says what to add."""
    header = (
        "# written by `tlmpc import-map`: the workspace is the free space of an occupancy-grid\n"
        "# map (configuration space when a radius was given); see docs/robot-data.md\n"
    )
    missing = unfinished(document)
    if missing:
        header += (
            f"# still to add: {' and '.join(missing)} (docs/mission-format.md), e.g.\n"
            "#   regions:\n#     dock: {rect: [XMIN, YMIN, XMAX, YMAX]}\n"
            "#   task: [visit dock]\n# then run `tlmpc check` on this file\n"
        )
    return header + yaml.safe_dump(
        dict(document), sort_keys=False, default_flow_style=None, width=100
    )
