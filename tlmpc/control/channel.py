"""The shortest path through a plan's channel of triangles (string pulling), as waypoints.

A plan is a sequence of triangles; consecutive ones share an edge, the *portal* the robot
crosses (a vertex passage crosses a single point, a portal of zero width).  The shortest path
from the start through the portals in order is found by the funnel algorithm ("simple stupid
funnel"): it keeps the apex of the shortest paths found so far and the two sides of the
funnel of directions that still see every later portal, and makes a side's end the next
apex when the other side crosses over it.  The path bends only at portal ends.

The triangles are those of the planning layout, which meshes the free space already eroded
by the body radius and the margin, so the channel, and any path through its portals, keeps
the body's clearance.

Each portal is first shrunk toward its midpoint by :data:`PORTAL_INSET` of its length at both
ends: an affine field's vertex conditions push every vertex of a portal across it, so a flow
line can only cross a portal strictly between its ends, and a little away from them the
controller has room to follow the path (see docs/control.md).  The insets are then widened,
and the string pulled again, where a piece could not be a flow line (:func:`_reachable`) or
passes a region's own corner closer than its clearance (:func:`_cleared`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

from tlmpc.abstraction.layout import GOAL_DEPTH_TIME

#: A point of the plane as Python floats.
Point = tuple[float, float]

#: Each portal keeps this fraction of its length clear at both ends.
PORTAL_INSET = 0.03
#: An end on an exposed label boundary (a region's own edge or corner) keeps the step's
#: clearance, so that the path does not graze a region it must avoid (the verifier's
#: robustness, the distance to the nearest boundary that decides the verdict, would vanish
#: with it), but at most this fraction of the portal ...
LABEL_INSET = 0.25
#: ... and at most this fraction where the plan enters a new label (so that the path goes
#: into the region it visits rather than grazing its edge).
ENTERED_INSET = 0.4


def label_clearance(max_speed: float) -> float:
    """The distance a path keeps from a region's own boundary it must not graze: what the
    robot covers at ``max_speed`` in :data:`tlmpc.abstraction.layout.GOAL_DEPTH_TIME`, the
    depth a goal is entered to by default (the same robustness, and the same certificate,
    for a region to stay clear of as for one to visit)."""
    return GOAL_DEPTH_TIME * max_speed


@dataclass(frozen=True, slots=True)
class Portal:
    """A crossing: ``left`` and ``right`` ends as seen facing the direction of travel
    (equal for a vertex passage)."""

    left: Point
    right: Point


@dataclass(frozen=True, slots=True)
class ChannelStep:
    """One plan step as the channel sees it: the triangle's counter-clockwise corners, the
    local index of the vertex opposite the exit edge (None for a stay), and the corner a vertex
    passage goes through (None otherwise)."""

    corners: tuple[Point, Point, Point]
    exit_edge: int | None
    #: The distance the path keeps from a label boundary it must not graze (a region's own
    #: boundary), along the exit portal (see :func:`_exit_insets`): what a compile passes is
    #: :func:`label_clearance` of the robot's max_speed.
    clearance: float
    through: Point | None = None
    #: Per corner: does it lie on a label boundary (a region's edge)?
    labelled: tuple[bool, bool, bool] = (False, False, False)
    #: Does the plan enter a new label in this triangle (its label differs from the last)?
    entered: bool = False
    #: Does a corner lie on a wall (the workspace's boundary or an obstacle's)?
    by_wall: bool = False


@dataclass(frozen=True, slots=True)
class Guide:
    """The straight piece of the channel's shortest path inside one step's triangle: from
    ``entry`` (the start, or where the path crosses the entry portal) to ``exit`` (where it
    crosses the exit portal; a stay's target)."""

    entry: Point
    exit: Point


def _cross(origin: Point, a: Point, b: Point) -> float:
    """(a - origin) x (b - origin): positive when b lies left of the ray origin -> a."""
    return (a[0] - origin[0]) * (b[1] - origin[1]) - (a[1] - origin[1]) * (b[0] - origin[0])


def inset(portal: Portal, left: float = PORTAL_INSET, right: float = PORTAL_INSET) -> Portal:
    """``portal`` shrunk toward its midpoint by ``left`` and ``right`` of its length at its
    two ends."""
    (lx, ly), (rx, ry) = portal.left, portal.right
    dx, dy = rx - lx, ry - ly
    return Portal((lx + left * dx, ly + left * dy), (rx - right * dx, ry - right * dy))


def exit_portal(step: ChannelStep) -> Portal:
    """The portal a step leaves by: its exit edge, or the corner of a vertex passage.

    For a counter-clockwise triangle the edge opposite vertex e runs from corner e + 1 to
    corner e + 2 with the interior on its left, so facing outward corner e + 2 is on the left.
    """
    if step.through is not None:
        return Portal(step.through, step.through)
    assert step.exit_edge is not None
    e = step.exit_edge
    return Portal(step.corners[(e + 2) % 3], step.corners[(e + 1) % 3])


def funnel(start: Point, portals: Sequence[Portal], end: Point) -> list[Point]:
    """The point where the shortest path from ``start`` through ``portals`` (in order) to
    ``end`` crosses each portal.

    The funnel algorithm: the apex and the two sides are tightened portal by portal; when a
    side would cross the other, the other side's end is a corner of the path (the next apex)
    and the scan restarts after it.  The crossings of the straight pieces between corners
    with the portals they pass are then read off.
    """
    gates = [Portal(start, start), *portals, Portal(end, end)]
    corners: list[tuple[int, Point]] = [(0, start)]  # (gate index, point) of each apex
    apex, left, right = start, start, start
    apex_at = left_at = right_at = 0
    index = 1
    while index < len(gates):
        gate = gates[index]
        # The right side moves inward (left) when the gate's right end is not right of it.
        if _cross(apex, right, gate.right) >= 0.0:
            if apex == right or _cross(apex, left, gate.right) < 0.0:
                right, right_at = gate.right, index
            else:  # it crosses over the left side: the left end is a corner
                apex, apex_at = left, left_at
                corners.append((apex_at, apex))
                right, right_at = apex, apex_at
                index = apex_at + 1
                continue
        if _cross(apex, left, gate.left) <= 0.0:
            if apex == left or _cross(apex, right, gate.left) > 0.0:
                left, left_at = gate.left, index
            else:
                apex, apex_at = right, right_at
                corners.append((apex_at, apex))
                left, left_at = apex, apex_at
                index = apex_at + 1
                continue
        index += 1
    if corners[-1][0] != len(gates) - 1:
        corners.append((len(gates) - 1, end))
    crossings: list[Point] = []
    for (a_at, a), (b_at, b) in itertools.pairwise(corners):
        for at in range(a_at + 1, b_at + 1):
            if at == len(gates) - 1:
                break
            crossings.append(b if at == b_at else _meet(a, b, gates[at]))
    return crossings


def _meet(a: Point, b: Point, gate: Portal) -> Point:
    """Where the segment a -> b crosses ``gate`` (clamped onto it against rounding)."""
    (lx, ly), (rx, ry) = gate.left, gate.right
    ex, ey = rx - lx, ry - ly
    dx, dy = b[0] - a[0], b[1] - a[1]
    denominator = dx * ey - dy * ex
    if denominator == 0.0:  # parallel (or a point gate): the gate's nearer end
        return gate.left
    u = ((lx - a[0]) * dy - (ly - a[1]) * dx) / denominator
    u = min(1.0, max(0.0, u))
    return (lx + u * ex, ly + u * ey)


def _incenter(corners: tuple[Point, Point, Point]) -> Point:
    lengths = []
    for i in range(3):
        (ax, ay), (bx, by) = corners[(i + 1) % 3], corners[(i + 2) % 3]
        lengths.append(((bx - ax) ** 2 + (by - ay) ** 2) ** 0.5)
    total = sum(lengths)
    return (
        sum(w * c[0] for w, c in zip(lengths, corners, strict=True)) / total,
        sum(w * c[1] for w, c in zip(lengths, corners, strict=True)) / total,
    )


#: A lasso's cycle is pulled over this many laps and the middle lap's path is used: a lap
#: away from both ends of the string is (to within the portals' width) the periodic path.
LAPS = 3


def channel_guides(
    steps: Sequence[ChannelStep], loop_start: int | None, start: Point
) -> list[Guide | None]:
    """The shortest path's piece in each step (None for a vertex passage, whose pursuit law
    is fixed): :func:`channel_pieces` without the passages'."""
    return [
        None if step.through is not None else piece
        for step, piece in zip(steps, channel_pieces(steps, loop_start, start), strict=True)
    ]


def channel_pieces(
    steps: Sequence[ChannelStep], loop_start: int | None, start: Point
) -> list[Guide]:
    """The shortest path's piece in each step (a vertex passage's: to its corner).

    A plan that ends by staying is pulled from the start to the nearest point of the stay
    triangle's entry edge (where the plan's cost ends: the task is met on entering it), and
    its stay piece runs from there to the triangle's incenter (the stay field's target); a
    lasso over its prefix and :data:`LAPS` laps of its cycle, the prefix's steps taking the
    first pass and the cycle's steps the middle lap.
    """
    count = len(steps)
    stay = loop_start is None and steps[-1].exit_edge is None
    if loop_start is None:
        order = list(range(count))
        moving = order[:-1] if stay else order
    else:
        cycle = list(range(loop_start, count))
        order = list(range(loop_start)) + cycle * LAPS
        moving = order
    insets = [_exit_insets(steps[i]) for i in moving]
    crossings = _pulled(steps, moving, insets, start, nearest=stay)
    for _ in range(REACH_ROUNDS):
        wider = [
            _reachable(steps[i], insets[k], start if k == 0 else crossings[k - 1], crossings[k])
            for k, i in enumerate(moving)
        ]
        wider = _cleared(steps, moving, wider, start, crossings)
        if wider == insets:
            break
        insets = wider
        crossings = _pulled(steps, moving, insets, start, nearest=stay)
    end = _incenter(steps[-1].corners) if stay else crossings[-1] if crossings else start
    # The pass each step takes: its first in the prefix, the middle lap in the cycle.
    chosen: dict[int, int] = {}
    for position, i in enumerate(moving):
        lap = 0 if loop_start is None or i < loop_start else (position - loop_start) // len(cycle)
        if lap == (0 if loop_start is None or i < loop_start else LAPS // 2):
            chosen[i] = position
    guides: list[Guide] = []
    for i, step in enumerate(steps):
        if step.exit_edge is None and step.through is None:  # the stay: to its target
            entry = crossings[len(moving) - 1] if moving else start
            guides.append(Guide(entry, end))
            continue
        position = chosen[i]
        entry = start if position == 0 else crossings[position - 1]
        guides.append(Guide(entry, crossings[position]))
    return guides


#: Rounds of widening the exit insets where the path, as pulled, could not be followed, or
#: passes a region's corner closer than its clearance (:func:`_cleared`; three rounds left a
#: visit across a corner a few per cent short of it).
REACH_ROUNDS = 6
#: The inset asked where a piece heads toward a kept facet's line at the sine σ of its angle
#: to it: this times σ.
REACH_GAIN = 0.5
#: No end of a portal is inset by more than this fraction (the portal keeps its middle).
REACH_CAP = 0.45


def _exit_insets(step: ChannelStep) -> tuple[float, float]:
    """The fractions :func:`_pulled` keeps clear at the exit portal's left and right ends.

    Every end keeps :data:`PORTAL_INSET`.  An end on an exposed label boundary keeps the
    step's ``clearance`` (where the plan enters a new label, the exposed ends keep it too),
    but never more than :data:`LABEL_INSET` (:data:`ENTERED_INSET` where a label is entered)
    of the portal: those fractions alone kept the path metres from a region it only had to
    stay clear of on a wide portal, and the middle fifth of a goal's edge made a patrol's lap
    10 % longer, where the robustness and the certificate need the tenth of a metre a goal is
    entered to.  Where the plan enters a new label in a triangle by a wall both ends keep it
    (the path would otherwise hug the wall: the robustness is also the distance to leaving
    the workspace)."""
    if step.through is not None or step.exit_edge is None:
        return (0.0, 0.0)
    e = step.exit_edge
    exposed = (step.labelled[(e + 2) % 3], step.labelled[(e + 1) % 3])
    portal = exit_portal(step)
    length = math.dist(portal.left, portal.right)
    # the clearance as a fraction of the portal, at most the fraction it replaces
    share = step.clearance / length if length > 0.0 else 0.0
    fraction = ENTERED_INSET if step.entered else LABEL_INSET
    kept = max(PORTAL_INSET, min(fraction, share))
    if step.entered and step.by_wall:
        return (kept, kept)
    return (kept if exposed[0] else PORTAL_INSET, kept if exposed[1] else PORTAL_INSET)


def _pulled(
    steps: Sequence[ChannelStep],
    moving: Sequence[int],
    insets: Sequence[tuple[float, float]],
    start: Point,
    *,
    nearest: bool = False,
) -> list[Point]:
    """The crossings of the exit portals of ``moving`` with these insets, the path ending on
    the last portal: at its midpoint, or (``nearest``) at the point of it nearest the start
    through the portals before it (:data:`NEAREST_ROUNDS` rounds of moving the end to the
    point of the portal nearest the path's last corner before it)."""
    if not moving:
        return []
    portals = [inset(exit_portal(steps[i]), *insets[k]) for k, i in enumerate(moving)]
    last = portals.pop()
    end = ((last.left[0] + last.right[0]) / 2.0, (last.left[1] + last.right[1]) / 2.0)
    crossings = [*funnel(start, portals, end), end]
    if not nearest:
        return crossings
    best = (_length(start, crossings), crossings)
    for _ in range(NEAREST_ROUNDS):
        corner = _last_corner(start, crossings)
        moved = _nearest_on(last, corner)
        if moved == end:
            break
        end = moved
        crossings = [*funnel(start, portals, end), end]
        length = _length(start, crossings)
        if length < best[0]:
            best = (length, crossings)
    return best[1]


#: At most this many rounds of moving a stay's end along its entry edge (each a funnel; they
#: stop once the end stays put: the path's last straight piece then meets the edge at a right
#: angle or at an end, the shortest way to it since the distance is convex along the edge).
NEAREST_ROUNDS = 16


def _length(start: Point, points: Sequence[Point]) -> float:
    return sum(math.dist(a, b) for a, b in itertools.pairwise([start, *points]))


def _last_corner(start: Point, points: Sequence[Point]) -> Point:
    """The last point before the end of the polyline ``start, *points`` where it bends (the
    start when it bends nowhere)."""
    path = [start, *points]
    end = path[-1]
    for k in range(len(path) - 2, 0, -1):
        if abs(_cross(path[k], end, path[k - 1])) > 1e-12 * math.dist(path[k - 1], end) ** 2:
            return path[k]
    return start


def _nearest_on(portal: Portal, point: Point) -> Point:
    """The point of ``portal`` nearest ``point``."""
    (lx, ly), (rx, ry) = portal.left, portal.right
    ex, ey = rx - lx, ry - ly
    squared = ex * ex + ey * ey
    if squared == 0.0:
        return portal.left
    u = min(1.0, max(0.0, ((point[0] - lx) * ex + (point[1] - ly) * ey) / squared))
    return (lx + u * ex, ly + u * ey)


def _reachable(
    step: ChannelStep, insets: tuple[float, float], entry: Point, exit_: Point
) -> tuple[float, float]:
    """``insets`` widened where the piece entry -> exit could not be a flow line.

    At an end a of the exit edge the other facet through a is kept: the field at a points
    away from it, so near a the flow cannot approach that facet's line.  A piece that ends
    at the fraction λ of the exit edge from a, heading toward that line with the sine σ of
    its angle to it (σ > 0), needs a field there that mixes a's velocity with the far end's
    by λ; with both at most max_speed, λ >= σ is necessary for a flow at full speed along
    the piece.  The end's inset becomes at least σ (at most :data:`REACH_CAP`)."""
    if step.through is not None or step.exit_edge is None:
        return insets
    dx, dy = exit_[0] - entry[0], exit_[1] - entry[1]
    norm = math.hypot(dx, dy)
    if norm == 0.0:
        return insets
    e = step.exit_edge
    corners = step.corners
    widened = list(insets)
    # left end: corner e + 2, its other facet runs to corner e; right end: corner e + 1,
    # its other facet runs from corner e
    for side, (a, c) in enumerate((((e + 2) % 3, e), ((e + 1) % 3, e))):
        ax, ay = corners[a]
        cx, cy = corners[c]
        ex, ey = cx - ax, cy - ay
        length = math.hypot(ex, ey)
        if length == 0.0:
            continue
        # the facet's outward normal: the triangle's third corner lies on its other side
        nx, ny = ey / length, -ex / length
        (ox, oy) = corners[3 - a - c]
        if nx * (ox - ax) + ny * (oy - ay) > 0.0:
            nx, ny = -nx, -ny
        sigma = (nx * dx + ny * dy) / norm
        if REACH_GAIN * sigma > widened[side]:
            widened[side] = min(REACH_CAP, REACH_GAIN * sigma)
    return (widened[0], widened[1])


#: A widening for the clearance asks this much more than the shortfall's ratio (the path moves
#: when the insets do; without it the rounds end a hair short of the clearance).
CLEARANCE_SLACK = 1.01


def _cleared(
    steps: Sequence[ChannelStep],
    moving: Sequence[int],
    insets: Sequence[tuple[float, float]],
    start: Point,
    crossings: Sequence[Point],
) -> list[tuple[float, float]]:
    """``insets`` widened where a piece passes a region's own corner (an exposed end of its
    entry or exit portal) closer than its step's clearance, or, entering a region and leaving
    it across one corner, goes less than that deep: the piece's ends on portals through that
    corner are kept from it by the shortfall's ratio (times :data:`CLEARANCE_SLACK`) times
    where they cross now, at most :data:`REACH_CAP` of the portal."""
    widened = [list(pair) for pair in insets]
    for k, i in enumerate(moving):
        step = steps[i]
        if step.through is not None or step.exit_edge is None:
            continue
        entry = start if k == 0 else crossings[k - 1]
        exit_ = crossings[k]
        e = step.exit_edge
        before = steps[moving[k - 1]] if k > 0 else None
        # the entry portal's ends (the step before's exit portal)
        entry_ends: tuple[Point, ...] = ()
        if before is not None and before.through is None and before.exit_edge is not None:
            ends = exit_portal(before)
            entry_ends = (ends.left, ends.right)
        for side, corner in enumerate(((e + 2) % 3, (e + 1) % 3)):
            if not step.labelled[corner]:
                continue
            vertex = step.corners[corner]
            reached = _segment_distance(vertex, entry, exit_)
            # a region entered in its corner triangle and left at once: the corner both
            # portals share
            if step.entered and all(step.labelled) and vertex in entry_ends:
                reached = min(reached, _tip_depth(step, corner, entry, exit_))
            if not 0.0 < reached < step.clearance:
                continue
            # the piece's ends move away from the corner along their portals by the
            # shortfall's ratio (the distance and the depth grow in proportion)
            factor = CLEARANCE_SLACK * step.clearance / reached
            out = exit_portal(step)
            along = math.dist(vertex, exit_) / math.dist(out.left, out.right)
            widened[k][side] = min(REACH_CAP, max(widened[k][side], along * factor))
            if vertex in entry_ends:
                other = entry_ends.index(vertex)
                along = math.dist(vertex, entry) / math.dist(*entry_ends)
                widened[k - 1][other] = min(REACH_CAP, max(widened[k - 1][other], along * factor))
    return [(pair[0], pair[1]) for pair in widened]


def _segment_distance(point: Point, a: Point, b: Point) -> float:
    """The distance from ``point`` to the segment a b."""
    return math.dist(point, _nearest_on(Portal(a, b), point))


def _tip_depth(step: ChannelStep, corner: int, entry: Point, exit_: Point) -> float:
    """How deep the piece entry -> exit goes into the corner of its triangle at ``corner``
    between the triangle's two edges there: the largest, along the piece, of the smaller
    distance to the two edges' lines (each is linear along it)."""
    vertex = step.corners[corner]
    others = [step.corners[(corner + 1) % 3], step.corners[(corner + 2) % 3]]

    def line_distance(point: Point, towards: Point) -> float:
        length = math.dist(vertex, towards)
        return abs(_cross(vertex, towards, point)) / length if length > 0.0 else 0.0

    # the entry lies on one of the edges at the corner, the exit on the other (else no tip)
    on_entry = min(others, key=lambda w: line_distance(entry, w))
    on_exit = others[1] if on_entry is others[0] else others[0]
    far_exit = line_distance(exit_, on_entry)
    far_entry = line_distance(entry, on_exit)
    if far_exit + far_entry == 0.0:
        return 0.0
    return far_exit * far_entry / (far_exit + far_entry)
