"""A candidate plan whose path touches a region and turns back, realised by splitting edges.

The shortest way to visit a region and go on often only touches it: into its edge and back
out the way it came.  No plan on the mesh can do that (a plan never leaves a triangle by the
edge it entered by), so the plan crosses the region's first triangle to another of its edges,
and on a coarse mesh (a goal's core of two large triangles) that detour is long.  Here:

1. the mission is planned with U-turns allowed (the product with bounces, the moves weighing
   their midpoint lengths): its lasso turns around in some triangles;
2. for each U-turn (the run goes n -> t -> n across edge e), the point p of e where the path
   should touch t: the string is pulled through the run's portals with the U-turn's two
   crossings of e replaced by one point of e, and p moves to where the path's way through n,
   x -> p -> y, is shortest (the reflection of y across e's line), a few rounds;
3. e is split at p, and t and n with it (:func:`tlmpc.abstraction.touch.split_edges`), and the
   mission is planned again without U-turns on the refined mesh
   (:func:`tlmpc.planning.mission.replan`): it can now enter one half of t near p and leave
   by the other.

The candidate is one more plan for :func:`tlmpc.pipeline.shortest.plan_shortest` to compare
(its path's length and its exact time); nothing here is kept unless it is shorter and not
slower.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

from tlmpc.abstraction.model import Abstraction
from tlmpc.abstraction.touch import split_edges
from tlmpc.base.errors import TlmpcError
from tlmpc.control.channel import Point, Portal, funnel
from tlmpc.mission.model import Mission
from tlmpc.planning.mission import Planned, again, replan
from tlmpc.planning.timing import MoveTimes


def touch_candidate(mission: Mission, planned: Planned, times: MoveTimes) -> Planned | None:
    """``planned`` planned again on its mesh refined where a plan with U-turns would touch a
    triangle and turn back (see the module doc); None when that plan has no such U-turn or
    either plan fails."""
    from tlmpc.planning.plan import plan

    mesh = planned.abstraction
    start = mission.robot.start
    try:
        bouncing = plan(mesh, planned.automaton, **again(mission, planned, times), bounces=True)
    except TlmpcError:
        return None
    if bouncing.passages:
        return None  # a run through a vertex: the string below is pulled across edges only
    run = [*bouncing.prefix, *bouncing.cycle]
    if not bouncing.is_stay:
        run += [*bouncing.cycle, bouncing.cycle[0]]
    splits = touch_points(mesh, run, start)
    if not splits:
        return None
    refined = split_edges(mesh, splits, start)
    if refined is mesh:
        return None
    try:
        return replan(mission, replace(planned, abstraction=refined), times)
    except TlmpcError:
        return None


def touch_points(
    mesh: Abstraction, run: Sequence[int], start: tuple[float, float]
) -> list[tuple[int, int, float]]:
    """``(t, edge, u)`` for each U-turn n -> t -> n of ``run`` (a sequence of adjacent
    triangles): t's local edge facing n and the fraction along it (from its corner
    ``edge + 1``) where the path should touch t.

    The string is pulled through the run's portals with each U-turn's two crossings of its
    edge replaced by one point of that edge (first its middle); each point then moves to
    where the path's way into and out of n, x -> p -> y, is shortest (:func:`_touch`), and
    the string is pulled again, :data:`TOUCH_ROUNDS` times.
    """
    turns = [
        i
        for i in range(1, len(run) - 1)
        if run[i - 1] == run[i + 1] and run[i - 1] in mesh.neighbors[run[i]].tolist()
    ]
    turns = [i for k, i in enumerate(turns) if k == 0 or turns[k - 1] < i - 1]
    if not turns:
        return []
    edges: dict[int, tuple[int, Point, Point]] = {}
    for i in turns:
        t, n = run[i], run[i - 1]
        edge = mesh.neighbors[t].tolist().index(n)
        corners = mesh.triangles[t].tolist()
        edges[i] = (
            edge,
            _point(mesh, corners[(edge + 1) % 3]),
            _point(mesh, corners[(edge + 2) % 3]),
        )
    fraction = dict.fromkeys(turns, 0.5)
    around = set(turns)
    end = _centroid(mesh, run[-1])
    for _ in range(TOUCH_ROUNDS):
        gates: list[Portal] = []
        at: dict[int, int] = {}  # U-turn -> index of its point among the gates
        k = 0
        while k < len(run) - 1:
            if k + 1 in around:  # n -> t -> n: one point of the edge
                _, a, b = edges[k + 1]
                u = fraction[k + 1]
                p = (a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]))
                at[k + 1] = len(gates)
                gates.append(Portal(p, p))
                k += 2
                continue
            portal = _portal(mesh, run[k], run[k + 1])
            if portal is None:
                return []
            gates.append(portal)
            k += 1
        path = [start, *funnel(start, gates, end), end]
        for i in turns:
            _, a, b = edges[i]
            x, y = path[at[i]], path[at[i] + 2]
            fraction[i] = _touch(a, b, x, y)
    found: list[tuple[int, int, float]] = []
    seen: set[int] = set()
    for i in turns:
        if run[i] in seen:
            continue
        seen.add(run[i])
        found.append((run[i], edges[i][0], fraction[i]))
    return found


#: Rounds of moving the touch points and pulling the string again.
TOUCH_ROUNDS = 3


def _touch(a: Point, b: Point, x: Point, y: Point) -> float:
    """The fraction u in [0, 1] along a -> b of the point p minimising |x p| + |p y| (x and y
    on the same side of the line): where x -> y', y' the reflection of y across the line,
    meets it."""
    ex, ey = b[0] - a[0], b[1] - a[1]
    length2 = ex * ex + ey * ey
    if length2 == 0.0:
        return 0.5
    # the reflection of y across the line a-b
    t = ((y[0] - a[0]) * ex + (y[1] - a[1]) * ey) / length2
    foot = (a[0] + t * ex, a[1] + t * ey)
    mirrored = (2 * foot[0] - y[0], 2 * foot[1] - y[1])
    dx, dy = mirrored[0] - x[0], mirrored[1] - x[1]
    denominator = dx * ey - dy * ex
    if abs(denominator) <= 1e-15 * math.sqrt(length2) * (abs(dx) + abs(dy) + 1e-300):
        return min(1.0, max(0.0, t))  # x on the line, or x -> y' along it
    u = ((a[0] - x[0]) * dy - (a[1] - x[1]) * dx) / denominator
    return min(1.0, max(0.0, u))


def _portal(mesh: Abstraction, a: int, b: int) -> Portal | None:
    """The edge from triangle a into b, left and right facing b (None unless they share one)."""
    sides = mesh.neighbors[a].tolist()
    if b not in sides:
        return None
    e = sides.index(b)
    corners = mesh.triangles[a].tolist()
    return Portal(_point(mesh, corners[(e + 2) % 3]), _point(mesh, corners[(e + 1) % 3]))


def _point(mesh: Abstraction, vertex: int) -> Point:
    x, y = mesh.vertices[vertex].tolist()
    return (float(x), float(y))


def _centroid(mesh: Abstraction, triangle: int) -> Point:
    x, y = mesh.corners(triangle).mean(axis=0).tolist()
    return (float(x), float(y))
