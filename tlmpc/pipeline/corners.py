"""A candidate plan on the mesh cut into rings where its path bends round a corner.

The path the fields follow bends at the ends of portals (the channel's corners).  A field can
cross its exit edge only a fraction of that edge away from the corner it turns round (the
portal insets; and a field running at full speed along a piece that heads toward a wall
needs as much), so on a fan of long edges the robot swings wide of the corner.  Here the
kept plan's path is pulled, every corner it bends round is cut into rings of smaller
triangles (:func:`tlmpc.abstraction.corner.ring_corners`), and the mission is planned
again on that mesh: one more candidate for :func:`tlmpc.pipeline.shortest.plan_shortest`,
kept when its trajectory is shorter and it is not slower than the midpoint plan.  A second
candidate first meshes the route's corridor finer
(:func:`tlmpc.abstraction.corridor.refine_corridor`: on a mesh of large triangles the
fields stray from the path everywhere, not only round its corners) and then cuts its rings.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass, replace

import numpy as np

from tlmpc.abstraction.corner import RING_FRACTION, ring_corners, ring_inradius
from tlmpc.abstraction.corridor import refine_corridor
from tlmpc.abstraction.model import Abstraction, triangle_inradius
from tlmpc.base.errors import TlmpcError
from tlmpc.control.channel import LABEL_INSET, Guide, label_clearance
from tlmpc.control.clearance import exposed_vertices, label_boundary
from tlmpc.control.follow import PlanStep, path_guides, turn_sine
from tlmpc.control.synthesize import plan_steps
from tlmpc.mission.model import Mission
from tlmpc.planning.mission import Planned, replan
from tlmpc.planning.product import SLOTS, move_lengths
from tlmpc.planning.timing import MoveTimes, move_key

#: A corner is cut when the path turns by more than this sine there (about 6°).
TURN = 0.1
#: ... and passes it within this fraction of the portal (the corner is the funnel's apex).
NEAR = 0.34
#: Rings cut about each corner (each halves the edges about it).
RINGS = 3
#: The re-plan on the cut mesh weighs moves outside the kept plan's triangles this many
#: times their midpoint length (it keeps to the kept channel, now cut finer).
CORRIDOR = 1.5
#: The refined corridor's triangles have edges about this fraction of the kept plan's path
#: (prefix and one lap) long.
ROUTE_SHARE = 0.06


@dataclass(frozen=True, slots=True)
class Bends:
    """A plan's path as its fields follow it, read once for both of its candidates."""

    #: The pulled path's pieces, one per plan step (None where a step has none).
    guides: tuple[Guide | None, ...]
    #: The mesh vertices the path bends round (:func:`tlmpc.control.follow.bend_corners`).
    corners: tuple[int, ...]
    #: The plan's triangles, and the smallest inradius among them.
    route: frozenset[int]
    floor: float


def followed_path(
    mission: Mission,
    planned: Planned,
    steps: Sequence[PlanStep],
    loop_start: int | None,
) -> list[Guide | None]:
    """The shortest path through ``planned``'s channel (its ``steps``,
    :func:`tlmpc.control.synthesize.plan_steps`) as the mission's controllers follow it: the
    label clearance of its max_speed kept from the regions its task names, a vertex
    passage's piece to its corner included."""
    return path_guides(
        planned.abstraction,
        steps,
        loop_start,
        mission.robot.start,
        passages=True,
        clearance=label_clearance(mission.robot.max_speed),
        relevant=mission.formula.props(),
    )


def plan_bends(mission: Mission, planned: Planned) -> Bends | None:
    """``planned``'s path as its fields follow it (None when its steps cannot be read)."""
    mesh = planned.abstraction
    try:
        steps, loop_start = plan_steps(mesh, planned.witness)
    except TlmpcError:
        return None
    guides = followed_path(mission, planned, steps, loop_start)
    corners = bend_corners(mesh, [(s.triangle, s.exit_edge) for s in steps], guides, loop_start)
    route = frozenset({*planned.witness.prefix, *planned.witness.cycle})
    floor = min(triangle_inradius(mesh.corners(t)) for t in route)
    return Bends(tuple(guides), tuple(corners), route, floor)


def corner_candidate(
    mission: Mission, planned: Planned, bends: Bends, *, refine: bool = False
) -> Planned | None:
    """``planned`` planned again on its mesh cut into rings about the corners its path
    (``bends``, :func:`plan_bends`) bends round (:func:`ring_counts` of them each), the moves
    in its own triangles' pieces weighing their midpoint lengths and the others
    :data:`CORRIDOR` times theirs (so the plan keeps to its channel, now cut finer); None
    when it bends round no corner that takes a ring, or the plan fails.

    With ``refine`` the route's corridor is first meshed again into triangles of edges about
    :data:`ROUTE_SHARE` of the path's length
    (:func:`tlmpc.abstraction.corridor.refine_corridor`), none thinner than the label
    clearance unless the plan's own triangles are; None when it is not refined."""
    mesh = planned.abstraction
    start = mission.robot.start
    clearance = label_clearance(mission.robot.max_speed)
    relevant = mission.formula.props()
    route, floor, corners = bends.route, bends.floor, bends.corners
    base, parent_of = mesh, list(range(mesh.num_triangles))
    if refine:
        # A piece as thin as the clearance is finer than anything the labels promise; the
        # runtime's default sample period, a tenth of the smallest inradius over the speed,
        # stays at least a hundredth of a second.
        floor = min(floor, clearance)
        length = sum(math.dist(g.entry, g.exit) for g in bends.guides if g is not None)
        # A plan ending by staying keeps the triangles of its stay's label whole: the plan on
        # the finer mesh would stay in a piece by the goal's edge (the cost ends where the
        # stay triangle is entered), and the robot converge there, not inside the goal.
        stay: list[int] = []
        if planned.witness.is_stay:
            letter = mesh.letter_of[planned.witness.cycle[0]]
            stay = np.flatnonzero(mesh.letter_of == letter).tolist()
        base, finer = refine_corridor(
            mesh, route, start, size=ROUTE_SHARE * length, floor=floor, keep=stay
        )
        if base is mesh:
            return None
        parent_of += finer
    refined, parents = ring_corners(
        base, ring_counts(base, corners, clearance, floor, relevant), start
    )
    if refined is mesh:
        return None
    parent_of += [parent_of[p] for p in parents]
    corridor = [t for t in range(refined.num_triangles) if parent_of[t] in route]
    lengths = move_lengths(refined, start)
    measured = {
        move_key(refined, t, slot, edge): float(lengths[t, slot, edge])
        for t in corridor
        for slot in range(SLOTS)
        for edge in range(3)
    }
    times = MoveTimes(speed=1.0 / CORRIDOR, measured=measured)
    try:
        return replan(mission, replace(planned, abstraction=refined), times)
    except TlmpcError:
        return None


def ring_counts(
    mesh: Abstraction,
    corners: Sequence[int],
    clearance: float,
    floor: float,
    relevant: Collection[str] | None = None,
) -> dict[int, int]:
    """How many rings to cut about each of ``corners``: at most :data:`RINGS`, and

    * no more than leave every triangle about the corner an inradius of at least ``floor``
      (:func:`tlmpc.abstraction.corner.ring_inradius`; a compile passes the smallest of the
      kept plan's triangles: the runtime's default sample period,
      :func:`tlmpc.runtime.closed_loop.default_dt`, is a fraction of it, so the rings never
      make a run take more samples, nor a robot's controller switch fields faster, than the
      plan's own triangles do; on a refined corridor, at most the label clearance);
    * about a corner on the own boundary of a ``relevant`` region (all when None)
      (:func:`tlmpc.control.clearance.exposed_vertices`) no more than keep its edges long
      enough for the path to keep ``clearance`` from it (an end there keeps at most
      :data:`tlmpc.control.channel.LABEL_INSET` of its portal: more rings would bring the
      path nearer the region than the clearance the channel promises, and the robustness
      with it).

    A corner where not even one ring fits is left out."""
    boundary = label_boundary(mesh)
    exposed = exposed_vertices(mesh, (v for v in corners if boundary[v]), relevant)
    counts: dict[int, int] = {}
    for v in dict.fromkeys(corners):
        kept = math.inf
        if v in exposed:
            star = mesh.triangles[np.nonzero(mesh.triangles == v)[0]]
            edges = mesh.vertices[star[star != v]] - mesh.vertices[v]
            kept = float(np.hypot(*edges.T).min()) * LABEL_INSET  # what the shortest keeps
        count = 0
        while (
            count < RINGS
            and RING_FRACTION ** (count + 1) * kept >= clearance
            and ring_inradius(mesh, v, count + 1) >= floor
        ):
            count += 1
        if count > 0:
            counts[v] = count
    return counts


def bend_corners(
    mesh: Abstraction,
    steps: Sequence[tuple[int, int | None]],
    guides: Sequence[Guide | None],
    loop_start: int | None,
) -> list[int]:
    """The mesh vertices the path bends round: for each step (triangle, exit edge) whose piece
    of the path and the next step's turn by more than :data:`TURN`, the end of the exit
    edge on the inside of the turn, when the path crosses the edge within :data:`NEAR` of
    it."""
    found: list[int] = []
    pairs = [(i, i + 1) for i in range(len(steps) - 1)]
    if loop_start is not None:
        pairs.append((len(steps) - 1, loop_start))
    for before, after in pairs:
        triangle, edge = steps[before]
        first, second = guides[before], guides[after]
        if edge is None or first is None or second is None:
            continue
        turn = turn_sine(first, second)  # (0 where either piece is a point)
        if abs(turn) <= TURN:
            continue
        corners = mesh.triangles[triangle].tolist()
        # facing out of a counter-clockwise triangle, corner edge + 2 is on the left
        inner = corners[(edge + 2) % 3] if turn > 0 else corners[(edge + 1) % 3]
        outer = corners[(edge + 1) % 3] if turn > 0 else corners[(edge + 2) % 3]
        width = math.dist(mesh.vertices[inner].tolist(), mesh.vertices[outer].tolist())
        if math.dist(first.exit, mesh.vertices[inner].tolist()) <= NEAR * width:
            found.append(inner)
    return found
