"""Configuration space of a robot with a body, and what the body cannot reach.

The reference point of a robot of radius r may go where the disc of radius r around it stays
in the free space: the free space eroded by r (shapely's buffer with round joins, by
:func:`~tlmpc.mission.body.conservative_offset` so that even the chords of the arcs keep r).
When the body is wider than a passage, the eroded free space splits; the diagnostics here say
where, in the user's terms:

* R001 (error): the start is closer to an obstacle than the body radius;
* R002 (warning): a passage narrower than the body splits the free space (its place, width and
  the obstacles that pinch it);
* R003 (warning): a region lies wholly within the body radius of obstacles;
* R004 (warning): a region the point robot could reach is cut off from the start by the body.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import shapely

from tlmpc.base.errors import Diagnostic, error
from tlmpc.mission.body import ARC_SEGMENTS, body_radius, conservative_offset, obstacle_offset
from tlmpc.mission.model import Mission, Point, Polygon

#: At most this many R002 warnings (the last one says how many more there are).
MAX_PINCHES = 5


def raw_free_space(boundary: Polygon, holes: Sequence[Polygon]) -> Any:
    """The boundary polygon minus the holes (no body)."""
    free = shapely.Polygon(boundary)
    if holes:
        free = free.difference(shapely.union_all([shapely.Polygon(h) for h in holes]))
    return free


def workspace_free_space(mission: Mission) -> Any:
    """The free space of every piece of the workspace (no body)."""
    pieces = [raw_free_space(c.boundary, c.holes) for c in mission.workspace.pieces]
    return pieces[0] if len(pieces) == 1 else shapely.union_all(pieces)


def erode(free: Any, distance: float) -> Any:
    """``free`` shrunk so that every point of the result is at least ``distance`` from its
    complement (conservatively: see the module docstring)."""
    if distance <= 0.0:
        return free
    return free.buffer(-conservative_offset(distance), quad_segs=ARC_SEGMENTS)


def configuration_space(mission: Mission) -> Any:
    """Where the reference point may be: the free space eroded by the body radius."""
    return erode(workspace_free_space(mission), obstacle_offset(mission))


@dataclass(frozen=True, slots=True, kw_only=True)
class Pinch:
    """A passage narrower than the body: its two closest points and the rings bounding it.

    Rings are numbered 0 for the boundary and k for the k-th hole (1-based).
    """

    width: float
    a: Point
    b: Point
    rings: tuple[int, int]

    @property
    def middle(self) -> Point:
        """The middle of the passage."""
        return ((self.a[0] + self.b[0]) / 2.0, (self.a[1] + self.b[1]) / 2.0)

    def describe(self) -> str:
        """``a passage 0.5 wide at (x, y) between hole 2 and the boundary``."""
        names = [("the boundary" if r == 0 else f"hole {r}") for r in self.rings]
        x, y = self.middle
        between = (
            f"two parts of {names[0]}" if names[0] == names[1] else f"{names[0]} and {names[1]}"
        )
        return f"a passage {self.width:.4g} wide at ({x:.6g}, {y:.6g}) between {between}"


def _parts(geometry: Any) -> list[Any]:
    return [g for g in shapely.get_parts(geometry) if not g.is_empty and g.area > 0.0]


def splitting_pinches(mission: Mission, cspace: Any, home: Any = None) -> list[Pinch]:
    """The passages narrower than the body that separate parts of the free space.

    Candidates are the narrowest gaps between pairs of rings (boundary, holes) that cross
    free space and are narrower than the body's diameter.  All of them are cut out of the
    free space at once (a thin slit along each gap); a passage separates when the pieces on
    its two sides differ and each holds some configuration space, so a blocked shortcut
    beside an open way round is not reported, and neither of two narrow passages side by
    side escapes.  With ``home`` (the part of the configuration space the robot starts in),
    only passages between it and the rest count: those cut the robot off from somewhere.
    """
    from tlmpc.mission.holes import passages_narrower_than

    radius = conservative_offset(obstacle_offset(mission))
    candidates = passages_narrower_than(
        mission.workspace.boundary, mission.workspace.holes, width=2.0 * radius
    )
    if not candidates:
        return []
    raw = raw_free_space(mission.workspace.boundary, mission.workspace.holes)
    minx, miny, maxx, maxy = raw.bounds
    slit = 1e-7 * max(maxx - minx, maxy - miny)
    cuts = [shapely.LineString([a, b]) for _, a, b, _ in candidates]
    pieces = _parts(raw.difference(shapely.union_all([c.buffer(slit) for c in cuts])))
    room = [p.intersection(cspace) for p in pieces]
    holds = [r.area > 0.0 for r in room]
    at_home = [home is not None and r.intersection(home).area > 0.0 for r in room]
    away = [home is None or r.difference(home).area > 0.0 for r in room]
    tree = shapely.STRtree(pieces)
    found: list[Pinch] = []
    for (width, a, b, rings), cut in zip(candidates, cuts, strict=True):
        sides = [i for i in tree.query(cut.buffer(2.0 * slit)).tolist() if holds[i]]
        if home is None:
            splits = len(set(sides)) >= 2
        else:
            splits = any(at_home[i] and any(away[j] for j in sides if j != i) for i in sides)
        if splits:
            found.append(Pinch(width=width, a=a, b=b, rings=rings))
    return found


def _lines(mission: Mission, text: str | None) -> dict[tuple[Any, ...], int]:
    """Lines of the robot start, boundary, holes and regions in the mission file."""
    from tlmpc.mission.yamlpos import load_positioned

    if mission.source is None:
        return {}
    try:
        source = text if text is not None else Path(mission.source).read_text(encoding="utf-8")
    except OSError:
        return {}
    doc = load_positioned(source, mission.source)[0]
    if doc is None:
        return {}
    keys: list[tuple[Any, ...]] = [("robot", "start"), ("workspace", "boundary")]
    keys += [("workspace", "holes", i) for i in range(len(mission.workspace.holes))]
    keys += [("regions", r.name) for r in mission.regions]
    lines: dict[tuple[Any, ...], int] = {}
    for key in keys:
        try:
            lines[key] = doc.value_at(key)[0]
        except (KeyError, IndexError, TypeError):
            continue
    return lines


def _nearest_obstacle(mission: Mission, point: Point) -> tuple[float, str]:
    """Distance from ``point`` to the nearest obstacle, and its name."""
    location = shapely.Point(point)
    best = (shapely.Polygon(mission.workspace.boundary).exterior.distance(location), "the boundary")
    for number, hole in enumerate(mission.workspace.holes, start=1):
        distance = shapely.Polygon(hole).distance(location)
        if distance < best[0]:
            best = (distance, f"hole {number}")
    return best


def body_diagnostics(mission: Mission, text: str | None = None) -> list[Diagnostic]:
    """R001-R004 for a robot with a body (none for a point robot)."""
    radius = body_radius(mission.robot)
    if radius <= 0.0:
        return []
    lines = _lines(mission, text)
    file = mission.source
    cspace = configuration_space(mission)
    problems: list[Diagnostic] = []
    start = shapely.Point(mission.robot.start)
    if not cspace.covers(start):
        distance, name = _nearest_obstacle(mission, mission.robot.start)
        problems.append(
            error(
                "R001",
                f"the start {mission.robot.start} is {distance:.4g} from {name}: the robot's "
                f"body (radius {radius:g}) overlaps it",
                hint="move the start away from the obstacle or give a smaller robot.radius",
                file=file,
                line=lines.get(("robot", "start")),
            )
        )
        return problems
    parts = _parts(cspace)
    home = next((p for p in parts if p.covers(start)), None)
    # the widest first: a passage almost wide enough is the one a user expects to be open
    pinches = sorted(splitting_pinches(mission, cspace, home), key=lambda p: -p.width)
    for count, pinch in enumerate(pinches):
        if count == MAX_PINCHES:
            problems[-1] = dataclasses.replace(
                problems[-1],
                message=problems[-1].message
                + f" (and {len(pinches) - MAX_PINCHES} more such passages)",
            )
            break
        ring = max(pinch.rings)
        key = ("workspace", "holes", ring - 1) if ring > 0 else ("workspace", "boundary")
        problems.append(
            Diagnostic(
                code="R002",
                severity="warning",
                message=f"{pinch.describe()} is narrower than the robot (diameter "
                f"{2 * radius:g}): the free space splits there",
                hint="widen the passage, or give a smaller robot.radius / footprint",
                file=file,
                line=lines.get(key),
            )
        )
    raw = workspace_free_space(mission)
    raw_home = next((p for p in _parts(raw) if p.covers(start)), None)
    shapes = [shapely.Polygon(r.polygon) for r in mission.regions]
    # a region with an interior point inside the robot's part is reachable: the usual case,
    # decided for all regions at once (maps with thousands of rooms)
    inner = shapely.get_coordinates([s.representative_point() for s in shapes])
    if home is not None and len(shapes):
        shapely.prepare(home)
        easy = shapely.contains_xy(home, inner[:, 0], inner[:, 1]).tolist()
    else:
        easy = [False] * len(shapes)
    for region, shape, reachable in zip(mission.regions, shapes, easy, strict=True):
        if reachable:
            continue
        line = lines.get(("regions", region.name))
        if not cspace.intersects(shape) or cspace.intersection(shape).area <= 0.0:
            if raw.intersection(shape).area > 0.0:
                problems.append(
                    Diagnostic(
                        code="R003",
                        severity="warning",
                        message=f"region {region.name!r} lies wholly within the robot's "
                        f"radius ({radius:g}) of obstacles: the robot cannot enter it",
                        hint="enlarge the region or give a smaller robot.radius / footprint",
                        file=file,
                        line=line,
                    )
                )
            continue
        reachable_by_point = raw_home is not None and raw_home.intersection(shape).area > 0.0
        if home is None or not reachable_by_point or home.intersection(shape).area > 0.0:
            continue
        # the splitting passages nearest to the region: usually the one in its way
        blocking = sorted(pinches, key=lambda p: shape.distance(shapely.Point(p.middle)))[:3]
        where = "; blocked by " + "; ".join(p.describe() for p in blocking) if blocking else ""
        problems.append(
            Diagnostic(
                code="R004",
                severity="warning",
                message=f"region {region.name!r} cannot be reached by the robot's body "
                f"(radius {radius:g}) from the start{where}",
                hint="widen the passages to it, or give a smaller robot.radius / footprint",
                file=file,
                line=line,
            )
        )
    return problems
