"""Configuration space of a robot with a body, and what the body cannot reach.

The reference point of a robot of radius r may go where the disc of radius r around it stays
in the free space: the free space eroded by r (:func:`erode`: exact along walls, within 2e-5
of r outside obstacle corners, never closer; plus two steps of the snapping grid, which the
mesh's vertices may move by).
When the body is wider than a passage, the eroded free space splits; the diagnostics here say
where, in the user's terms:

* R001 (error): the start is closer to an obstacle than the body radius (measured exactly: a
  start exactly the radius away is legal);
* R002 (warning): a passage narrower than the body splits the free space (its place, width and
  the obstacles that pinch it);
* R003 (warning): a region lies wholly within the body radius of obstacles;
* R004 (warning): a region the point robot could reach is cut off from the start by the body.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import shapely

from tlmpc.base.errors import Diagnostic, error
from tlmpc.mission.body import body_radius, obstacle_offset
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


#: The polygon standing in for a disc's arc around an obstacle corner has a side tangent to
#: the circle at least every this many radians: it lies outside the circle (so it keeps the
#: whole disc off the corner) and at most ``1 / cos(ARC_STEP / 2) - 1`` (0.48 %) of the
#: distance beyond it.
ARC_STEP = 2.0 * math.pi / 32

#: Chords per quarter circle of the round buffer in :func:`erode` (its radius is enlarged so
#: that the chords, not the vertices, lie at the distance: 0.48 % more at corners).
QUAD_SEGS = 8

#: Features of an eroded free space thinner than twice this (relative to the map's
#: coordinates) are overlay artefacts, not space (the snapping grid is a billionth).
SPIKE_WIDTH = 1e-12


def erode(free: Any, distance: float, *, slack: float = 0.0, through: Point | None = None) -> Any:
    """``free`` shrunk to the points at least ``distance`` (plus ``slack``) from its
    complement.

    Shapely's buffer alone is not enough: its arcs are chords inside the circle, and GEOS
    simplifies its input by up to 1 % of the distance.  The reach of the complement is taken
    as the intersection of two buffers of ``free``'s boundary that each hold every point
    within the distance of it: a mitred one at exactly the distance (exact along walls; a
    mitre, or a bevel twice the distance out, lies outside the circle at a corner) and a
    round one whose chords, not vertices, lie at the distance (0.48 % beyond it at corners).
    The result is then *proved*: the exact distance from each of its boundary segments to
    the boundary of ``free`` must be at least the distance.  Where GEOS's simplification
    broke that, the exact construction replaces it (each edge's rectangle and each obstacle
    corner's sector bounded by tangent sides; slower on large maps).  So the result keeps
    the distance exactly along walls, within 0.48 % of it at obstacle corners, and never
    less; points at exactly the distance from a wall stay in it.

    ``slack`` is an absolute allowance added to the distance (the snapping grid, so that a
    snapped mesh still keeps it).  With a point ``through`` at least the distance from every
    obstacle, the exact construction is used, and beside an obstacle corner that corner's
    tangent sides are cut by the tangent line through the point, so the point stays in.
    """
    if distance <= 0.0:
        return free
    reach = distance + slack
    if through is None:
        boundary = shapely.boundary(free)
        round_band = boundary.buffer(
            reach / math.cos(math.pi / (4 * QUAD_SEGS)), quad_segs=QUAD_SEGS
        )
        mitred = boundary.buffer(reach, join_style="mitre", mitre_limit=2.0)
        # GEOS can return an invalid mitred buffer (nested shells beside a wall thinner than
        # the distance), on which the overlay raises or erodes wrongly: the exact
        # construction below needs no buffer.
        if round_band.is_valid and mitred.is_valid:
            eroded = _polygonal(free.difference(round_band.intersection(mitred)))
            if keeps_distance(eroded, free, reach):
                return eroded
    near = obstacle_reach(free, reach, through)
    if near is None:
        return free
    eroded = _polygonal(free.difference(near))
    if not keeps_distance(eroded, free, reach):
        # The overlay can leave a spike of no width running out to an obstacle's corner
        # where two sides of the reach coincide: an opening far below the snapping grid
        # removes it and nothing else (it keeps a subset of ``eroded``).
        width = SPIKE_WIDTH * _scale(free, reach)
        opened = eroded.buffer(-width, join_style="mitre").buffer(width, join_style="mitre")
        eroded = _polygonal(opened.intersection(eroded))
    return eroded


def _polygonal(geometry: Any) -> Any:
    parts = [p for p in shapely.get_parts(shapely.make_valid(geometry)) if not p.is_empty]
    polygons = [p for p in parts if isinstance(p, shapely.Polygon)]
    return shapely.union_all(polygons) if polygons else shapely.Polygon()


def keeps_distance(inner: Any, free: Any, distance: float) -> bool:
    """True when every point of ``inner`` is at least ``distance`` (to rounding) from the
    boundary of ``free``: measured exactly, segment against segment (the least distance from
    a point of ``inner`` to the outside is reached on ``inner``'s boundary)."""
    mine = _segments(inner)
    walls = _segments(free)
    if not len(mine) or not len(walls):
        return True
    tree = shapely.STRtree(walls)
    _, gaps = tree.query_nearest(mine, return_distance=True, all_matches=False)
    return bool(np.min(gaps) >= distance - 1e-12 * _scale(free, distance))


def _scale(free: Any, distance: float) -> float:
    """The magnitude the rounding of distances in ``free`` is relative to."""
    return max(float(np.abs(shapely.get_coordinates(free)).max()), distance)


def _segments(geometry: Any) -> Any:
    lines = []
    for ring in shapely.get_parts(shapely.boundary(geometry)):
        coords = shapely.get_coordinates(ring)
        if len(coords) >= 2:
            lines.append(np.stack([coords[:-1], coords[1:]], axis=1))
    if not lines:
        return np.empty(0, dtype=object)
    return shapely.linestrings(np.concatenate(lines))


def obstacle_reach(free: Any, distance: float, through: Point | None = None) -> Any:
    """A polygon holding every point of ``free`` within ``distance`` of its boundary, built
    exactly (see :func:`erode`); None when ``free`` has no boundary."""
    from shapely.geometry.polygon import orient

    pieces: list[Any] = []
    for polygon in shapely.get_parts(free):
        if not isinstance(polygon, shapely.Polygon) or polygon.is_empty:
            continue
        # counter-clockwise exterior, clockwise holes: the free space is on each edge's left
        oriented = orient(polygon, 1.0)
        for ring in (oriented.exterior, *oriented.interiors):
            corners = np.asarray(ring.coords, dtype=np.float64)[:-1]
            pieces.extend(_ring_reach(corners, distance, through))
    if not pieces:
        return None
    return shapely.union_all(pieces)


def _ring_reach(ring: Any, distance: float, through: Point | None) -> list[Any]:
    """The edges' rectangles and the obstacle corners' sectors of one ring (free space on
    its left)."""
    ahead = np.roll(ring, -1, axis=0)
    edge = ahead - ring
    length = np.hypot(edge[:, 0], edge[:, 1])
    keep = length > 0.0
    ring, ahead, edge, length = ring[keep], ahead[keep], edge[keep], length[keep]
    if len(ring) < 2:
        return []
    left = np.stack([-edge[:, 1], edge[:, 0]], axis=1) / length[:, None]  # into free space
    offset = distance * left
    rectangles = np.stack([ring - offset, ahead - offset, ahead + offset, ring + offset], axis=1)
    shapes: list[Any] = list(shapely.polygons(rectangles))
    # corner k joins edge k-1 (arriving) and edge k (leaving) at ring[k]
    before = np.roll(left, 1, axis=0)
    arriving = np.roll(edge, 1, axis=0)
    turn = arriving[:, 0] * edge[:, 1] - arriving[:, 1] * edge[:, 0]
    reflex = np.flatnonzero(turn <= 0.0)  # right turns: an obstacle's corner
    if not len(reflex):
        return shapes
    starts = np.arctan2(before[reflex, 1], before[reflex, 0])
    ends = np.arctan2(left[reflex, 1], left[reflex, 0])
    sweeps = -np.mod(starts - ends, 2.0 * math.pi)  # clockwise from the arriving normal
    for k, start, sweep in zip(reflex.tolist(), starts.tolist(), sweeps.tolist(), strict=True):
        if sweep >= 0.0:
            continue
        sector = _sector(ring[k], distance, start, sweep)
        if through is not None:
            sector = _tangent_through(sector, ring[k], distance, through)
        shapes.append(sector)
    return shapes


def _tangent_through(sector: Any, centre: Any, radius: float, point: Point) -> Any:
    """``sector`` cut by the line tangent to the circle through ``point`` when the point lies
    in the sector's polygon and no nearer to the centre than ``radius``: what is cut off is
    outside the disc, and the point is then on the boundary, not inside."""
    dx, dy = point[0] - float(centre[0]), point[1] - float(centre[1])
    away = math.hypot(dx, dy)
    if away < radius * (1.0 - 1e-12) or not sector.covers(shapely.Point(point)):
        return sector
    ux, uy = dx / away, dy / away
    far = 4.0 * radius + away  # beyond the sector on every side
    x, y = point
    # the half-plane on the centre's side of the tangent line through ``point``
    keep = shapely.Polygon(
        [
            (x - far * uy, y + far * ux),
            (x + far * uy, y - far * ux),
            (x + far * uy - far * ux, y - far * ux - far * uy),
            (x - far * uy - far * ux, y + far * ux - far * uy),
        ]
    )
    return sector.intersection(keep)


def _sector(centre: Any, radius: float, start: float, sweep: float) -> Any:
    """A polygon holding the disc sector from angle ``start`` through ``sweep`` radians: the
    centre, the two end points on the circle, and between them the corners of sides tangent
    to the circle (so the arc lies inside)."""
    count = max(1, math.ceil(abs(sweep) / ARC_STEP))
    half = sweep / (2 * count)
    corner = radius / math.cos(half)
    x, y = float(centre[0]), float(centre[1])
    points = [(x, y), (x + radius * math.cos(start), y + radius * math.sin(start))]
    for j in range(count):
        angle = start + (2 * j + 1) * half
        points.append((x + corner * math.cos(angle), y + corner * math.sin(angle)))
    end = start + sweep
    points.append((x + radius * math.cos(end), y + radius * math.sin(end)))
    return shapely.Polygon(points)


def configuration_space(mission: Mission) -> Any:
    """Where the reference point may be: the free space eroded by the body radius (and two
    steps of the snapping grid, which the planner's mesh may move by; see :func:`erode`)."""
    return erode(
        workspace_free_space(mission), obstacle_offset(mission), slack=2.0 * _grid(mission)
    )


def _grid(mission: Mission) -> float:
    from tlmpc.mission.grid import grid_size

    return grid_size(mission)


def start_clearance(mission: Mission) -> float:
    """The exact distance from the start to the nearest obstacle (0 outside the free
    space): the body fits there when this is at least the radius."""
    free = workspace_free_space(mission)
    start = shapely.Point(mission.robot.start)
    if not free.covers(start):
        return 0.0
    return float(free.boundary.distance(start))


def start_fits(mission: Mission) -> bool:
    """True when the body around the start meets no obstacle (touching one is allowed: a
    start exactly the radius from a wall is legal), to the rounding of the distance."""
    offset = obstacle_offset(mission)
    x, y = mission.robot.start
    rounding = 1e-12 * max(abs(x), abs(y), offset, 1.0)
    return start_clearance(mission) >= offset - rounding


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
        return f"a passage {self.width:.7g} wide at ({x:.6g}, {y:.6g}) between {between}"


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

    radius = obstacle_offset(mission) + 2.0 * _grid(mission)
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


def _imported_from(name: str, workspace: dict[str, Any]) -> tuple[Any, ...]:
    """Where the mask that region ``name`` came from is named (``keepout_K`` from the
    keepout mask, ``speed_V_K`` from the speed mask), else the map itself."""
    mask = name.split("_", 1)[0]
    if mask in ("keepout", "speed") and mask in workspace:
        return ("workspace", mask)
    return ("workspace", "map")


def _places(mission: Mission, text: str | None) -> dict[tuple[Any, ...], tuple[int, int]]:
    """(line, col) in the mission file of the robot start, boundary, holes and regions, keyed
    by their paths in a mission that draws its workspace.

    A workspace taken from a map (``workspace: {map: ...}``) has its boundary and holes where
    the map is named, and each region imported from a mask where that mask is named: neither
    is written in the mission, whose nearest written ancestor (``regions:``) would point at
    another region.
    """
    from tlmpc.mission.yamlpos import load_positioned

    if mission.source is None:
        return {}
    try:
        source = text if text is not None else Path(mission.source).read_text(encoding="utf-8")
    except OSError:
        return {}
    doc = load_positioned(source, mission.source)[0]
    if doc is None or not isinstance(doc.data, dict):
        return {}
    workspace = doc.data.get("workspace")
    workspace = workspace if isinstance(workspace, dict) else {}
    on_map = "map" in workspace
    written = doc.data.get("regions")
    written = written if isinstance(written, dict) else {}
    keys: list[tuple[Any, ...]] = [("robot", "start"), ("workspace", "boundary")]
    keys += [("workspace", "holes", i) for i in range(len(mission.workspace.holes))]
    keys += [("regions", r.name) for r in mission.regions]
    places: dict[tuple[Any, ...], tuple[int, int]] = {}
    for key in keys:
        at = key
        if on_map and key[0] == "workspace":
            at = ("workspace", "map")
        elif on_map and key[0] == "regions" and key[1] not in written:
            at = _imported_from(key[1], workspace)
        try:
            places[key] = doc.value_at(at)
        except (KeyError, IndexError, TypeError):
            continue
    return places


def _nearest_obstacle(mission: Mission, point: Point) -> tuple[float, str]:
    """Distance from ``point`` to the nearest obstacle, and its name."""
    location = shapely.Point(point)
    best = (shapely.Polygon(mission.workspace.boundary).exterior.distance(location), "the boundary")
    for number, hole in enumerate(mission.workspace.holes, start=1):
        distance = shapely.Polygon(hole).distance(location)
        if distance < best[0]:
            best = (distance, f"hole {number}")
    return best


def _too_narrow(pinch: Pinch, mission: Mission, radius: float) -> str:
    """Why ``pinch`` splits the free space, with the width the body needs (its diameter,
    and twice the map tolerance on an occupancy map) measured exactly."""
    needed = 2.0 * obstacle_offset(mission)
    body = f"diameter {2.0 * radius:g}"
    if needed > 2.0 * radius:
        body += f" plus twice the map tolerance {mission.workspace.map_tolerance:g}"
    if pinch.width < needed:
        return (
            f"{pinch.describe()} is narrower than the {needed:.7g} the robot's body needs "
            f"({body}): the free space splits there"
        )
    return (
        f"{pinch.describe()} leaves the robot's body (it needs {needed:.7g}: {body}) less "
        f"than the planner's resolution ({_grid(mission):g}) to spare: the free space "
        "splits there"
    )


def body_diagnostics(mission: Mission, text: str | None = None) -> list[Diagnostic]:
    """R001-R004 for a robot with a body (none for a point robot)."""
    radius = body_radius(mission.robot)
    if radius <= 0.0:
        return []
    places = _places(mission, text)
    file = mission.source
    cspace = configuration_space(mission)
    problems: list[Diagnostic] = []
    start = shapely.Point(mission.robot.start)
    if not start_fits(mission):
        distance, name = _nearest_obstacle(mission, mission.robot.start)
        line, col = places.get(("robot", "start"), (None, None))
        problems.append(
            error(
                "R001",
                f"the start {mission.robot.start} is {distance:.4g} from {name}: the robot's "
                f"body (radius {radius:g}) overlaps it",
                hint="move the start away from the obstacle or give a smaller robot.radius",
                file=file,
                line=line,
                col=col,
            )
        )
        return problems
    parts = _parts(cspace)
    # a start exactly the radius from a wall lies within the grid of its part, not in it
    near = [(p.distance(start), i) for i, p in enumerate(parts)]
    home = parts[min(near)[1]] if near and min(near)[0] <= 4.0 * _grid(mission) else None
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
        line, col = places.get(key, (None, None))
        problems.append(
            Diagnostic(
                code="R002",
                severity="warning",
                message=_too_narrow(pinch, mission, radius),
                hint="widen the passage, or give a smaller robot.radius / footprint",
                file=file,
                line=line,
                col=col,
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
        line, col = places.get(("regions", region.name), (None, None))
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
                        col=col,
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
                col=col,
            )
        )
    return problems
