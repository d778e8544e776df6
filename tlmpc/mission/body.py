"""The robot's body: one radius the planner keeps off obstacles, and the requested margin.

Everything that inflates obstacles asks :func:`body_radius`, so a new kind of body (a
unicycle's point ahead of the axle, say) changes one function.
"""

from __future__ import annotations

import math

from tlmpc.mission.model import Mission, Robot

#: Quarter circles of an offset curve are approximated by this many chords (shapely's
#: ``quad_segs``).
ARC_SEGMENTS = 8

#: Relative allowance for the offset machinery itself: GEOS simplifies a buffer's input line
#: by up to 1% of the distance before offsetting, and snapping to the triangulation grid
#: moves vertices by a billionth of the map; 2% covers both with room to spare.
OFFSET_SLACK = 0.02


def body_radius(robot: Robot) -> float:
    """The radius of the disc that contains the robot's body in every heading.

    A footprint polygon is replaced by its circumscribed disc about the reference point (the
    robot may turn anywhere, so the planner cannot count on a heading); with both a radius
    and a footprint, the larger disc; a unicycle's disc grows by its ``offset``.
    """
    radius = robot.radius
    if robot.footprint:
        radius = max(radius, max(math.hypot(x, y) for x, y in robot.footprint))
    # A unicycle's labels and plan follow the point ``offset`` ahead of its axle: the body,
    # carried by the axle, reaches that much further from the reference point.
    return radius + unicycle_inflation(robot)


def unicycle_inflation(robot: Robot) -> float:
    """How much farther than its reference point the robot's axle can reach: ``offset`` for
    a unicycle, 0 for a point robot (added to the body radius when inflating holes)."""
    return robot.offset if robot.model == "unicycle" else 0.0


def obstacle_offset(mission: Mission) -> float:
    """How far the reference point keeps from the mission's obstacles: the body radius, plus
    the workspace's ``map_tolerance`` for a body on an occupancy map (its simplified rings may
    lie that far inside the occupied cells); 0 for a point robot."""
    radius = body_radius(mission.robot)
    return radius + mission.workspace.map_tolerance if radius > 0.0 else 0.0


#: Where a diagnostic about the margin is placed: at ``options.margin``, or, when it is the
#: default (the body radius), at its nearest written parent.
MARGIN_PATH = "$.options.margin"


def requested_margin(mission: Mission) -> float:
    """``options.margin`` as given, else the default: the body radius (0 for a point robot)."""
    if mission.options.margin is not None:
        return mission.options.margin
    return body_radius(mission.robot)


def conservative_offset(distance: float) -> float:
    """The buffer distance that keeps at least ``distance`` despite chord approximations.

    Shapely draws an offset arc as chords between points on the circle, which come as close
    as ``d * cos(pi / (4 * ARC_SEGMENTS))`` to the centre; buffering by this larger distance
    puts even the chords at least ``distance`` away.
    """
    if distance <= 0.0:
        return 0.0
    return distance * (1.0 + OFFSET_SLACK) / math.cos(math.pi / (4 * ARC_SEGMENTS))
