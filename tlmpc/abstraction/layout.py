"""The geometry the planner triangulates for a robot with a body and a margin.

* **Free space**: the configuration space (free space eroded by the body radius, exactly, plus
  two steps of the snapping grid) and, with a margin m, eroded by m more; when the robot starts
  closer than that to a wall (in the margin band, or exactly the radius away), the
  configuration space without the grid's step is kept in a disc around the start (twice its
  way out, plus m), so it can still leave the wall.
* **Regions** keep their names, and the labels are the reference point's, but the shapes that
  label the triangles change with the task (its negation normal form):

  - a region that occurs only positively (a goal: visit, stay, reach) labels its **core**, the
    region eroded by its goal depth (:func:`goal_depth`: at least m, by default a quarter of
    its inradius but at most what the robot covers in 0.1 s at max_speed; by half its
    inradius when that is smaller: then the core is a small patch around its pole of
    inaccessibility), so that a visit is a visit and not a touch;
  - a region that occurs only negatively (avoid it) labels its **grown** shape, the region
    dilated by m (when the robot starts within m of it, except within 2 m of the start);
  - a region of both polarities, or not in the task, keeps its shape, and so does a region
    a reactive mission's assumptions name (:func:`region_polarities`).

A task is monotone in each proposition of one polarity, so a run that satisfies it with the
cores and grown shapes satisfies it with the true regions: planning here is sound, and
every guarantee of the later stages carries over to the true labels.  It may be infeasible
where the plain mission is not; the plan stage then plans without the goal depth, then
without the margin, and says so.

A point robot without margin keeps the mission's own free space and the shapes of the regions
that are not goals (``free`` and those shapes are ``None`` in its layout): only its goals'
cores change the mesh.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import shapely

from tlmpc.ltl.polarity import Polarity, polarities
from tlmpc.mission.body import ARC_SEGMENTS, conservative_offset, obstacle_offset
from tlmpc.mission.cspace import erode, workspace_free_space
from tlmpc.mission.grid import grid_size
from tlmpc.mission.model import Mission

#: A robot that starts in a margin band may use the band within this many times the distance
#: out of it (the straight way out may be blocked; a wider disc leaves room to turn).
ESCAPE = 2.0

#: The erosion's allowance for snapping, in grid steps (see :func:`planning_layout`).
SNAP_SLACK = 2.0

#: ... and, however near the band's edge it starts, within this many grid steps of the start
#: (a smaller patch would be a sliver of the grid's size in the mesh).
START_ROOM = 1e3

#: The default goal depth (``options.goal_depth`` unset) is the least of two: this fraction
#: of the goal region's inradius (a small region is entered visibly, half way from the
#: boundary to the cap of half the inradius, so goals that overlap keep cores that meet) ...
GOAL_DEPTH_FRACTION = 0.25
#: ... and the distance the robot covers at ``max_speed`` in this many seconds.  A visit that
#: goes d deep lasts at least 2 d / max_speed, so a log sampled at least every 2 x this
#: (0.2 s: 5 Hz) at up to max_speed has a sample inside the region, and the verifier's
#: certificate (the robot within max_speed x half a gap of a sample) can prove the visit.
#: A fixed fraction of the inradius alone made every visit to a large room cost half a metre
#: or more of detour (Example 6: 1.17 x the shortest path for the depth alone).
GOAL_DEPTH_TIME = 0.1
#: ... but never less than this fraction of the workspace's extent: a slow robot on a large
#: map would otherwise get a rim between core and region far thinner than anything else the
#: mesh holds (a quality mesh fills a strip of width w along a perimeter p with about p / w
#: triangles), and a core within a millionth of the extent of its region's edge would count
#: as that edge (:mod:`tlmpc.control.clearance`).
GOAL_DEPTH_FLOOR = 1e-3


@dataclass(frozen=True, slots=True, kw_only=True)
class PlanningLayout:
    """Free space and region shapes to triangulate (shapely geometries, regions in order).

    ``free`` None: the mission's own free space; a region's shape None: its own polygon (a
    point robot without margin, whose goals alone are cored)."""

    free: Any
    regions: tuple[Any, ...]
    margin: float
    radius: float


def inradius(region: Any) -> float:
    """The radius of the largest disc in ``region`` (about its pole of inaccessibility)."""
    from shapely.ops import polylabel

    size = max(region.bounds[2] - region.bounds[0], region.bounds[3] - region.bounds[1])
    pole = polylabel(region, tolerance=1e-3 * size)
    radius = float(region.exterior.distance(pole))
    for interior in region.interiors:
        radius = min(radius, float(interior.distance(pole)))
    return radius


def default_goal_depth(region: Any, max_speed: float, extent: float = 0.0) -> float:
    """The goal depth when ``options.goal_depth`` is unset: :data:`GOAL_DEPTH_FRACTION` of
    ``region``'s inradius, at most ``max_speed`` x :data:`GOAL_DEPTH_TIME` but not below
    :data:`GOAL_DEPTH_FLOOR` x the workspace's ``extent``."""
    fraction = GOAL_DEPTH_FRACTION * inradius(region)
    timed = max(GOAL_DEPTH_TIME * max_speed, GOAL_DEPTH_FLOOR * extent)
    return min(fraction, timed)


def goal_depth(
    region: Any,
    margin: float,
    requested: float | None,
    scale: float = 1.0,
    max_speed: float = 1.0,
    extent: float = 0.0,
) -> float:
    """How deep a path must go into the goal ``region``: the margin, or ``requested``
    (``options.goal_depth``; unset: :func:`default_goal_depth` at ``max_speed`` on a
    workspace of that ``extent``) times ``scale`` (a shallower try, see
    :func:`planning_layout`) when deeper.

    :func:`core` caps it at half the inradius."""
    wanted = default_goal_depth(region, max_speed, extent) if requested is None else requested
    return max(margin, scale * wanted)


def workspace_extent(mission: Mission) -> float:
    """The larger side of the workspace's bounding box."""
    xs = [x for piece in mission.workspace.pieces for x, _ in piece.boundary]
    ys = [y for piece in mission.workspace.pieces for _, y in piece.boundary]
    return max(max(xs) - min(xs), max(ys) - min(ys))


def core(region: Any, depth: float) -> Any:
    """``region`` eroded by ``depth``, or by half its inradius when it is thinner than that."""
    if depth <= 0.0:
        return region
    reach = conservative_offset(min(depth, 0.5 * inradius(region)))
    return region.buffer(-reach, quad_segs=ARC_SEGMENTS)


def deepens_goals(mission: Mission) -> bool:
    """Whether the goal depth asks more than the margin does (on some region)."""
    requested = mission.options.goal_depth
    return requested is None or requested > 0.0


def region_polarities(mission: Mission) -> dict[str, Polarity]:
    """Each region's polarity as the layout reads it: its polarity in the task, except that a
    region a reactive mission's assumptions name is ``both`` (it keeps its shape).

    The assumptions are the environment's promise about the true regions.  Where the mesh
    labels a core or a grown shape instead, the game's assumption differs from the real one:
    an environment that keeps the real promise can break the game's (the strategy then has
    no answer and the robot stops), and one that keeps the game's can break the real one."""
    signs = polarities(mission.formula)
    if mission.reactive is not None:
        for part in mission.reactive.assumptions:
            for name in polarities(part.formula):
                signs[name] = "both"
    return signs


def planning_layout(
    mission: Mission, margin: float, *, deep: bool = True, scale: float = 1.0
) -> PlanningLayout | None:
    """The layout for ``mission`` with ``margin`` and, with ``deep``, the goal depth (times
    ``scale``: the plan stage tries shallower goals when the cores' corners are too sharp
    for the disturbance); None for a point robot without margin whose goals keep their
    shapes."""
    radius = obstacle_offset(mission)
    deep = deep and deepens_goals(mission)
    if radius <= 0.0 and margin <= 0.0:
        return _point_layout(mission, scale) if deep else None
    raw = workspace_free_space(mission)
    # two steps of the snapping grid more: the free space is snapped, and then noded with the
    # regions' rings, each moving a vertex by up to a step's half diagonal
    grid = grid_size(mission)
    free = erode(raw, radius + max(margin, 0.0), slack=SNAP_SLACK * grid)
    start = shapely.Point(mission.robot.start)
    if not free.covers(start):
        # The robot starts in the margin band, or exactly the radius from a wall (legal:
        # R001 measures exactly): it may use the configuration space without the grid's
        # slack in a disc around the start, twice its way out plus the margin, so that it
        # can leave the band or the wall.
        way_out = free.distance(start) if not free.is_empty else 0.0
        reach = ESCAPE * way_out + conservative_offset(margin) + START_ROOM * grid
        near_start = start.buffer(reach, quad_segs=ARC_SEGMENTS)
        # only the obstacles near the start matter there: erode a window around it
        x, y = mission.robot.start
        half = reach + 2.0 * radius
        window = raw.intersection(shapely.box(x - half, y - half, x + half, y + half))
        exact = erode(window, radius, through=mission.robot.start)
        # Snapping moves the free space's vertices by up to a step's half diagonal: a start
        # less than that inside (off the grid, a hair more than the radius from a slanted wall
        # or a corner) would fall out of the snapped mesh.  A disc of one step round it keeps
        # it in; it reaches at most a step closer to an obstacle than the start itself is.
        keep_start = start.buffer(grid, quad_segs=ARC_SEGMENTS)
        kept = shapely.union(exact.intersection(near_start), keep_start)
        free = shapely.make_valid(shapely.union(free, kept))
    signs = region_polarities(mission) if margin > 0.0 or deep else {}
    shapes: list[Any] = []
    for region in mission.regions:
        shape = shapely.Polygon(region.polygon)
        sign = signs.get(region.name)
        if sign == "positive":
            requested = mission.options.goal_depth
            speed, extent = mission.robot.max_speed, workspace_extent(mission)
            depth = goal_depth(shape, margin, requested, scale, speed, extent) if deep else margin
            inner = core(shape, depth)
            shape = inner if not inner.is_empty else shape
        elif sign == "negative":
            grown = shape.buffer(conservative_offset(margin), quad_segs=ARC_SEGMENTS)
            if grown.covers(start) and not shape.covers(start):
                # the robot starts near the region: it may leave the band on its way out
                spared = start.buffer(ESCAPE * conservative_offset(margin), quad_segs=ARC_SEGMENTS)
                grown = grown.difference(spared)
            shape = shapely.union(shape, grown)
        shapes.append(shape)
    return PlanningLayout(free=free, regions=tuple(shapes), margin=margin, radius=radius)


def _point_layout(mission: Mission, scale: float = 1.0) -> PlanningLayout | None:
    """A point robot without margin: the mission's free space, its goals' cores at the goal
    depth, every other region as it is; None when the task visits no region."""
    signs = region_polarities(mission)
    shapes: list[Any] = []
    for region in mission.regions:
        shape: Any = None
        if signs.get(region.name) == "positive":
            polygon = shapely.Polygon(region.polygon)
            requested = mission.options.goal_depth
            speed, extent = mission.robot.max_speed, workspace_extent(mission)
            depth = goal_depth(polygon, 0.0, requested, scale, speed, extent)
            inner = core(polygon, depth)
            shape = inner if not inner.is_empty else None
        shapes.append(shape)
    if all(shape is None for shape in shapes):
        return None
    return PlanningLayout(free=None, regions=tuple(shapes), margin=0.0, radius=0.0)
