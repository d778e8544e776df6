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

The plan with U-turns weighs its moves by their midpoint lengths and may make no U-turn where
one would pay (a goal's core of one large triangle, crossed from corner to corner).
:func:`visit_touch_candidate` reads the kept plan's own path instead: where a visit could
touch its label's edge between the bends either side of it (:func:`visit_touches`), the edge
is split there and the plan made again with the moves round the split point weighing their
pieces of the touching path.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from tlmpc.abstraction.model import Abstraction
from tlmpc.abstraction.touch import EDGE_MARGIN, split_edges
from tlmpc.base.errors import TlmpcError
from tlmpc.control.channel import Guide, Point, Portal, _cross, funnel
from tlmpc.control.follow import turn_sine
from tlmpc.mission.model import Mission
from tlmpc.planning.mission import Planned, again, replan
from tlmpc.planning.product import STUTTER_COST
from tlmpc.planning.timing import MoveKey, MoveTimes, move_key


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


def visit_touch_candidate(mission: Mission, planned: Planned) -> Planned | None:
    """``planned`` planned again on its mesh split where its path (as its fields follow it,
    :func:`tlmpc.pipeline.corners.followed_path`) could touch the labels it visits instead
    of crossing into them (:func:`visit_touches`), the moves of the triangles round each
    split point weighing their pieces of the touching path (:func:`_pieces`; on the midpoint
    lengths the new spoke's middle, half way to the label's far corner, hides the touch) and
    the others their midpoint lengths; None when no visit gains or the plan fails."""
    from tlmpc.control.synthesize import plan_steps
    from tlmpc.pipeline.corners import followed_path

    mesh = planned.abstraction
    start = mission.robot.start
    try:
        steps, loop_start = plan_steps(mesh, planned.witness)
    except TlmpcError:
        return None
    guides = followed_path(mission, planned, steps, loop_start)
    touches = visit_touches(mesh, [s.triangle for s in steps], guides, loop_start)
    if not touches:
        return None
    refined = split_edges(mesh, [(t, edge, u) for t, edge, u, _, _ in touches], start)
    if refined is mesh:
        return None
    # split_edges appends one point per split it makes (it may skip some): each is paired
    # with the touch whose point of its edge it is
    wanted = [(_split_point(mesh, touch), touch[3], touch[4]) for touch in touches]
    measured: dict[MoveKey, float] = {}
    for vertex in range(len(mesh.vertices), len(refined.vertices)):
        p = _point(refined, vertex)
        _, x, y = min(wanted, key=lambda w: math.dist(w[0], p))
        measured.update(_pieces(refined, vertex, x, y))
    try:
        return replan(
            mission,
            replace(planned, abstraction=refined),
            MoveTimes(speed=1.0, measured=measured),
        )
    except TlmpcError:
        return None


def _split_point(mesh: Abstraction, touch: tuple[int, int, float, Point, Point]) -> Point:
    """The point of ``mesh`` where ``touch`` splits its edge."""
    t, edge, u, _, _ = touch
    corners = mesh.triangles[t].tolist()
    a, b = _point(mesh, corners[(edge + 1) % 3]), _point(mesh, corners[(edge + 2) % 3])
    return (a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]))


def _pieces(mesh: Abstraction, vertex: int, x: Point, y: Point) -> dict[MoveKey, float]:
    """The moves of the triangles round ``vertex`` along x -> p -> y (p the vertex, moved a
    hair into the angle's far side, :func:`_beside`, so that the path crosses edges, not the
    vertex), each weighing its piece of that path (:func:`_pieces_along`)."""
    path = _beside(_point(mesh, vertex), x, y)
    return {} if path is None else _pieces_along(mesh, vertex, path)


def _beside(p: Point, x: Point, y: Point) -> list[Point] | None:
    """x -> q -> y with q a millionth of the shorter leg from p, away from both x and y
    (along the bisector of the angle x p y); None when the angle is flat or a leg empty."""
    ux, uy = x[0] - p[0], x[1] - p[1]
    vx, vy = y[0] - p[0], y[1] - p[1]
    nu, nv = math.hypot(ux, uy), math.hypot(vx, vy)
    if nu == 0.0 or nv == 0.0:
        return None
    bx, by = -(ux / nu + vx / nv), -(uy / nu + vy / nv)
    nb = math.hypot(bx, by)
    if nb == 0.0:
        return None
    hair = 1e-6 * min(nu, nv)
    return [x, (p[0] + hair * bx / nb, p[1] + hair * by / nb), y]


def _pieces_along(mesh: Abstraction, vertex: int, path: Sequence[Point]) -> dict[MoveKey, float]:
    """The moves of the triangles round ``vertex`` that the polyline ``path`` makes (entering
    by one edge, leaving by another), each weighing its length inside."""
    star = np.nonzero((mesh.triangles == vertex).any(axis=1))[0].tolist()
    found: dict[MoveKey, float] = {}
    for t in star:
        corners = [_point(mesh, v) for v in mesh.triangles[t].tolist()]
        events: list[tuple[float, int]] = []
        travelled = 0.0
        for a, b in itertools.pairwise(path):
            for edge in range(3):
                c, d = corners[(edge + 1) % 3], corners[(edge + 2) % 3]
                hit = _crossing(a, b, c, d)
                if hit is not None:
                    events.append((travelled + hit * math.dist(a, b), edge))
            travelled += math.dist(a, b)
        events.sort()
        for (s1, e1), (s2, e2) in itertools.pairwise(events):
            if e1 != e2 and s2 > s1 and _inside(corners, _along(path, (s1 + s2) / 2.0)):
                found[move_key(mesh, t, e1, e2)] = (s2 - s1) + STUTTER_COST
    return found


def _along(path: Sequence[Point], distance: float) -> Point:
    """The point ``distance`` along the polyline ``path`` (its end beyond it)."""
    for a, b in itertools.pairwise(path):
        length = math.dist(a, b)
        if distance <= length and length > 0.0:
            f = distance / length
            return (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]))
        distance -= length
    return path[-1]


def _inside(corners: Sequence[Point], point: Point) -> bool:
    """Whether ``point`` lies in the triangle (either orientation)."""
    sides = [_cross(corners[k], corners[(k + 1) % 3], point) for k in range(3)]
    return all(side >= 0.0 for side in sides) or all(side <= 0.0 for side in sides)


def _crossing(a: Point, b: Point, c: Point, d: Point) -> float | None:
    """Where segment a-b crosses segment c-d, as a fraction along a-b (None: it does not)."""
    rx, ry = b[0] - a[0], b[1] - a[1]
    sx, sy = d[0] - c[0], d[1] - c[1]
    denominator = rx * sy - ry * sx
    if denominator == 0.0:
        return None
    t = ((c[0] - a[0]) * sy - (c[1] - a[1]) * sx) / denominator
    u = ((c[0] - a[0]) * ry - (c[1] - a[1]) * rx) / denominator
    return t if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0 else None


#: A visit is split where touching its label saves more than this fraction of the path
#: between the bends either side of it.
VISIT_GAIN = 0.01
#: The path bends where the sine of its turn exceeds this.
VISIT_BEND = 0.1
#: At most this many triangles of a visited label are searched for the best edge to touch.
VISIT_REACH = 64


def visit_touches(
    mesh: Abstraction,
    triangles: Sequence[int],
    guides: Sequence[Guide | None],
    loop_start: int | None,
) -> list[tuple[int, int, float, Point, Point]]:
    """``(t, edge, u, x, y)`` where the path (``guides``, one piece per plan step in ``triangles``)
    would be shorter touching a label it enters than crossing into it: for each visit (the
    steps from one entering a proposition the step before lacked, while the label stays), the
    path's bends x before it and y after it, and the edge of the visited label's patch
    facing out, and the point p on it, where x -> p -> y is shortest (:func:`_touch`); kept
    when that saves more than :data:`VISIT_GAIN` of the path from x to y."""
    order = list(range(len(triangles)))
    if loop_start is not None:
        order += list(range(loop_start, len(triangles)))  # a lap more: visits at its wrap
    points: list[Point] = []
    for k in order:
        guide = guides[k]
        if guide is not None:
            points.extend(p for p in (guide.entry, guide.exit) if not points or p != points[-1])
    bends = _bend_indices(points)
    cumulative = [0.0]
    for a, b in itertools.pairwise(points):
        cumulative.append(cumulative[-1] + math.dist(a, b))
    letters = [set(mesh.letters[int(mesh.letter_of[triangles[k]])]) for k in order]
    found: dict[int, tuple[int, float, Point, Point]] = {}
    q = 1
    cursor = 0  # the polyline is walked once: each visit's points after the last visit's
    while q < len(order):
        if not letters[q] - letters[q - 1]:
            q += 1
            continue
        end = q
        while end + 1 < len(order) and letters[end + 1] == letters[q]:
            end += 1
        guide_in, guide_out = guides[order[q]], guides[order[end]]
        if guide_in is None or guide_out is None or end + 1 >= len(order):
            q = end + 1
            continue
        entry = _index_of(points, guide_in.entry, after=cursor)
        leave = None if entry is None else _index_of(points, guide_out.exit, after=entry)
        if entry is None or leave is None:
            q = end + 1
            continue
        cursor = leave
        patch = _patch(mesh, [triangles[order[k]] for k in range(q, end + 1)])
        low, high = _box(mesh, patch)
        # the bends either side of the visit, not those the visit makes itself (at its label)
        before = [i for i in bends if i < entry and not _in_box(points[i], low, high)]
        after = [i for i in bends if i > leave and not _in_box(points[i], low, high)]
        x_at = before[-1] if before else 0
        y_at = after[0] if after else len(points) - 1
        x, y = points[x_at], points[y_at]
        now = cumulative[y_at] - cumulative[x_at]
        best = _best_touch(mesh, patch, x, y)
        if best is not None and best[0] < now * (1.0 - VISIT_GAIN):
            _, t, edge, u = best
            found.setdefault(t, (edge, u, x, y))
        q = end + 1
    return [(t, edge, u, x, y) for t, (edge, u, x, y) in found.items()]


def _bend_indices(points: Sequence[Point]) -> list[int]:
    """The inner points of a polyline where it turns by more than :data:`VISIT_BEND`."""
    return [
        i
        for i in range(1, len(points) - 1)
        if abs(turn_sine(Guide(points[i - 1], points[i]), Guide(points[i], points[i + 1])))
        > VISIT_BEND
    ]


def _index_of(points: Sequence[Point], point: Point, after: int = 0) -> int | None:
    for i in range(after, len(points)):
        if points[i] == point:
            return i
    return None


def _patch(mesh: Abstraction, visited: Sequence[int]) -> list[int]:
    """The triangles of the first visited triangle's letter reachable from the visited ones
    across edges (at most :data:`VISIT_REACH`)."""
    letter = int(mesh.letter_of[visited[0]])
    patch: list[int] = []
    queue = [int(t) for t in dict.fromkeys(visited) if int(mesh.letter_of[t]) == letter]
    seen = set(queue)
    while queue and len(patch) < VISIT_REACH:
        t = queue.pop(0)
        patch.append(t)
        for n in mesh.neighbors[t].tolist():
            if n >= 0 and n not in seen and int(mesh.letter_of[n]) == letter:
                seen.add(n)
                queue.append(n)
    return patch


def _box(mesh: Abstraction, patch: Sequence[int]) -> tuple[Point, Point]:
    """The patch's bounding box grown by a tenth of its diagonal."""
    corners = mesh.vertices[mesh.triangles[list(patch)]].reshape(-1, 2)
    low, high = corners.min(axis=0), corners.max(axis=0)
    grow = 0.1 * float(np.hypot(*(high - low)))
    return (
        (float(low[0]) - grow, float(low[1]) - grow),
        (float(high[0]) + grow, float(high[1]) + grow),
    )


def _in_box(point: Point, low: Point, high: Point) -> bool:
    return low[0] <= point[0] <= high[0] and low[1] <= point[1] <= high[1]


def _best_touch(
    mesh: Abstraction, patch: Sequence[int], x: Point, y: Point
) -> tuple[float, int, int, float] | None:
    """The shortest x -> p -> y over the edges of a label's ``patch`` (:func:`_patch`) that
    face a triangle of another letter on the side of both x and y: (length, t, edge, u)."""
    letter = int(mesh.letter_of[patch[0]])
    best: tuple[float, int, int, float] | None = None
    for t in patch:
        corners = mesh.triangles[t].tolist()
        for edge in range(3):
            n = int(mesh.neighbors[t, edge])
            if n < 0 or int(mesh.letter_of[n]) == letter:
                continue
            a = _point(mesh, corners[(edge + 1) % 3])
            b = _point(mesh, corners[(edge + 2) % 3])
            inside = _point(mesh, corners[edge])
            side = _cross(a, b, inside)
            if _cross(a, b, x) * side >= 0.0 or _cross(a, b, y) * side >= 0.0:
                continue  # x or y not across the edge from the label
            u = min(1.0 - EDGE_MARGIN, max(EDGE_MARGIN, _touch(a, b, x, y)))
            p = (a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]))
            length = math.dist(x, p) + math.dist(p, y)
            if best is None or length < best[0]:
                best = (length, t, edge, u)
    return best
