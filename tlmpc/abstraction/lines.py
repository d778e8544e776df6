"""The lines of the convex cells' meshes: the map's linework cut into convex faces.

Two decompositions, both convex faces of one label set each:

* the **arrangement**: each straight side of the free space's rings and of the regions'
  boundaries inside it is extended both ways to a full line, clipped to the free space. Every
  face is convex (a reflex corner of a face would need a side to end there, but every side
  goes on straight), and two faces that share a side share all of it (a vertex on it is where
  another line crosses, and that line bounds both faces): a cell move between two faces
  leaves by a whole side (:mod:`tlmpc.planning.cells`). It grows with the square of the
  number of sides, so it is built only up to :data:`MAX_SIDES` of them.
* the **reflex cuts**: only the faces' reflex corners are cut, each by rays shot into its
  face until the first hit of the linework (:func:`reflex_extensions`; an STRtree over the
  linework's segments, each ray's reach doubled until it hits): near-linear in the sides.
  A corner of angle a between 225 and 315 degrees gets both its sides extended (its three
  parts a - 180, 360 - a and a - 180 are all at least 45 degrees; a rectilinear map keeps its
  right angles), any other its bisector (two parts of a / 2, obtuse). Every corner of the
  result is at most 180 degrees (a cut corner's parts are below 180; where a ray ends on a
  side it makes two angles summing to 180, and a straight one on the side's far face; rays
  cross at four angles below 180), so every face is convex. A face across a side a ray ends
  on keeps a straight corner there (a T-junction): it meets two faces along that side, and
  a cell move to either keeps the other's part of the side (the cell fields allow that).
  Its work is counted (:data:`MAX_REFLEX_WORK`). Extended sides cross each other in open
  space (up to the square of the corners); the **bisector cuts** (every reflex corner cut by
  its bisector alone) cross less and, on maps of scattered polygons, keep wider corners.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
import shapely

#: The most sides extended (their arrangement has up to about sides^2 / 2 faces).
MAX_SIDES = 120

#: The reflex cuts' budget, in work units: one per reflex corner, one per ray and segment
#: whose boxes the STRtree pairs while shooting (each doubling of a ray's reach counts
#: again), and one per pair of cuts that meet (their crossings are vertices of the mesh).
#: Example 8 (1,156 rooms, 4,624 reflex corners) takes 63,788.
MAX_REFLEX_WORK = 1_000_000

#: A corner is reflex when its turn is below minus this, relative to its sides' lengths (the
#: convex cells' own collinearity tolerance).
COLLINEAR = 1e-8
#: Reflex corners within this many degrees of 270 get both sides extended; others a bisector.
SIDES_WITHIN = 45.0

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: The decompositions: every side extended across the free space, the reflex cuts (sides
#: extended near 270 degrees, bisectors elsewhere), or the reflex cuts by bisectors alone.
Lines = Literal["arrangement", "reflex", "bisector"]


class OverBudget(Exception):
    """The reflex cuts would take more than :data:`MAX_REFLEX_WORK` work units."""

    def __init__(self, work: int) -> None:
        super().__init__(f"the reflex cuts take more than their budget ({work} work units)")
        self.work = work


def side_count(rings: list[Any]) -> int:
    """The straight sides of ``rings``."""
    return sum(max(len(ring.coords) - 1, 0) for ring in rings)


def extended_lines(free: Any, rings: list[Any]) -> list[Any]:
    """Every side of ``rings`` extended to a full line, clipped to ``free`` (in ring order)."""
    minx, miny, maxx, maxy = free.bounds
    reach = 4.0 * math.hypot(maxx - minx, maxy - miny)
    found = []
    for ring in rings:
        coords = np.asarray(ring.coords, dtype=np.float64)
        for a, b in itertools.pairwise(coords):
            length = float(np.hypot(*(b - a)))
            if length == 0.0:
                continue
            direction = (b - a) / length
            line = shapely.LineString([a - reach * direction, b + reach * direction])
            clipped = line.intersection(free)
            if not clipped.is_empty:
                found.append(clipped)
    return found


@dataclass(frozen=True, slots=True)
class ReflexCuts:
    """The cuts of :func:`reflex_extensions`: segments from a reflex corner to the first hit
    of the linework, the reflex corners cut, and the work spent (``None`` segments: over
    the budget)."""

    segments: list[Any] | None
    corners: int
    work: int


def reflex_extensions(
    linework: Any, free: Any, budget: int | None = None, *, bisectors: bool = False
) -> ReflexCuts:
    """The cuts that make every face of ``linework`` (noded: segments meet at their ends)
    inside ``free`` convex (see the module doc), or no segments when they would take more
    than ``budget`` work units (default :data:`MAX_REFLEX_WORK`). With ``bisectors`` every
    reflex corner is cut by its bisector alone (one ray a corner: fewer cuts to cross)."""
    if budget is None:
        budget = MAX_REFLEX_WORK
    parts = np.asarray(list(shapely.get_parts(linework)), dtype=object)
    points, owner = shapely.get_coordinates(parts, return_index=True)
    joined = owner[1:] == owner[:-1]
    starts, ends = points[:-1][joined], points[1:][joined]
    faces = shapely.get_parts(shapely.polygonize(list(parts)))
    faces = faces[shapely.intersects(free, shapely.point_on_surface(faces))]
    within = -1.0 if bisectors else SIDES_WITHIN
    origins, directions, reach, corners = _rays(shapely.orient_polygons(faces), within)
    work = corners
    if not len(origins):
        return ReflexCuts(segments=[], corners=0, work=work)
    tree = shapely.STRtree(shapely.linestrings(np.stack([starts, ends], axis=1)))
    minx, miny, maxx, maxy = free.bounds
    farthest = 2.0 * math.hypot(maxx - minx, maxy - miny)
    hits = np.full(len(origins), np.inf)
    pending = np.arange(len(origins))
    while len(pending):
        tips = origins[pending] + reach[pending, None] * directions[pending]
        pairs = tree.query(
            shapely.linestrings(np.stack([origins[pending], tips], axis=1)), predicate="intersects"
        )
        work += pairs.shape[1]
        if work > budget:
            return ReflexCuts(segments=None, corners=corners, work=work)
        ray, segment = pending[pairs[0]], pairs[1]
        found = _first_hits(origins[ray], directions[ray], starts[segment], ends[segment])
        np.minimum.at(hits, ray, found)
        pending = pending[~np.isfinite(hits[pending])]
        reach[pending] *= 2.0
        pending = pending[reach[pending] <= 2.0 * farthest]  # inside the free space: never
    done = np.isfinite(hits)
    cuts = shapely.linestrings(
        np.stack([origins[done], origins[done] + hits[done, None] * directions[done]], axis=1)
    )
    crossing = shapely.STRtree(cuts).query(cuts, predicate="intersects")
    work += int(np.count_nonzero(crossing[0] < crossing[1]))
    if work > budget:
        return ReflexCuts(segments=None, corners=corners, work=work)
    return ReflexCuts(segments=list(cuts), corners=corners, work=work)


def _rays(faces: Any, within: float) -> tuple[FloatArray, FloatArray, FloatArray, int]:
    """The rays cutting the reflex corners of ``faces`` (oriented: the face on the left of
    every ring): origins, unit directions, a first reach (the corner's shorter side), and
    how many corners they cut. Corners within ``within`` degrees of 270 get both sides
    extended, the others their bisector."""
    rings = shapely.get_rings(faces)
    face_of_ring = np.repeat(np.arange(len(faces)), shapely.get_num_interior_rings(faces) + 1)
    coords, ring = shapely.get_coordinates(rings, return_index=True)
    last = np.r_[ring[1:] != ring[:-1], True]
    coords, ring = coords[~last], ring[~last]  # each ring's closing point dropped
    first = np.r_[0, np.flatnonzero(ring[1:] != ring[:-1]) + 1]
    size = np.diff(np.r_[first, len(ring)])
    start = np.repeat(first, size)
    local = np.arange(len(ring)) - start
    length = np.repeat(size, size)
    before = coords[start + (local - 1) % length]
    after = coords[start + (local + 1) % length]
    incoming, outgoing = coords - before, after - coords
    a = np.hypot(incoming[:, 0], incoming[:, 1])
    b = np.hypot(outgoing[:, 0], outgoing[:, 1])
    turn = incoming[:, 0] * outgoing[:, 1] - incoming[:, 1] * outgoing[:, 0]
    reflex = (turn < -COLLINEAR * a * b) & (a > 0.0) & (b > 0.0)
    origin = coords[reflex]
    forward = incoming[reflex] / a[reflex, None]  # the incoming side, extended on
    backward = -outgoing[reflex] / b[reflex, None]  # the outgoing side, extended back
    shorter = np.minimum(a[reflex], b[reflex])
    # the corner's angle inside the face: 180 plus its right turn
    dot = incoming[:, 0] * outgoing[:, 0] + incoming[:, 1] * outgoing[:, 1]
    angle = 180.0 - np.degrees(np.arctan2(turn[reflex], dot[reflex]))
    sides = np.abs(angle - 270.0) <= within
    bisector = forward + backward  # the two extensions' mean points into the face's middle
    bisector = bisector / np.hypot(bisector[:, 0], bisector[:, 1])[:, None]
    origins = np.concatenate([origin[sides], origin[sides], origin[~sides]])
    directions = np.concatenate([forward[sides], backward[sides], bisector[~sides]])
    reach = np.concatenate([shorter[sides], shorter[sides], shorter[~sides]])
    corner = np.flatnonzero(reflex)
    shot_from = np.concatenate([corner[sides], corner[sides], corner[~sides]])
    keep = _into_face(coords, before, after, face_of_ring[ring], shot_from, directions)
    return (
        origins[keep],
        directions[keep],
        reach[keep].astype(np.float64),
        int(np.count_nonzero(reflex)),
    )


def _into_face(
    coords: FloatArray,
    before: FloatArray,
    after: FloatArray,
    face: IntArray,
    shot_from: IntArray,
    directions: FloatArray,
) -> npt.NDArray[np.bool_]:
    """Which rays start into their face. A ray leaves its corner into the face as its own
    ring sees it, but where rings of one face touch at a point (a hole touching a region's
    side at a corner) the other rings' corners there take wedges of that side away: a ray
    into one of them would run through a hole or a region. Such a ray is dropped; the
    face's own wedges at the point are still cut (a wedge wider than 180 degrees holds a
    ray of the ring beside it: at 180 degrees from that ring's side, or its bisector)."""
    keep = np.ones(len(shot_from), dtype=bool)
    keys = np.concatenate([face[:, None].astype(np.float64), coords], axis=1)
    _, group, count = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    group = group.reshape(-1)
    pinched = count[group] > 1
    if not pinched[shot_from].any():
        return keep
    members: dict[int, list[int]] = {}
    for index in np.flatnonzero(pinched).tolist():
        members.setdefault(int(group[index]), []).append(index)
    for k in np.flatnonzero(pinched[shot_from]).tolist():
        own = int(shot_from[k])
        dx, dy = float(directions[k, 0]), float(directions[k, 1])
        for other in members[int(group[own])]:
            if other != own and not _in_wedge(coords[other], before[other], after[other], dx, dy):
                keep[k] = False
                break
    return keep


def _in_wedge(
    point: FloatArray, before: FloatArray, after: FloatArray, dx: float, dy: float
) -> bool:
    """Whether direction (dx, dy) from a ring's corner ``point`` lies strictly inside the
    face's wedge there: counter-clockwise from the side to ``after`` to the side to
    ``before`` (the face is on the left of its rings)."""
    ux, uy = float(after[0] - point[0]), float(after[1] - point[1])
    vx, vy = float(before[0] - point[0]), float(before[1] - point[1])
    turn = math.atan2(ux * vy - uy * vx, ux * vx + uy * vy) % math.tau or math.tau
    heading = math.atan2(ux * dy - uy * dx, ux * dx + uy * dy) % math.tau
    return 0.0 < heading < turn


def _first_hits(
    origin: FloatArray, direction: FloatArray, start: FloatArray, end: FloatArray
) -> FloatArray:
    """Per ray and segment that meet (the STRtree's exact test said so): how far along the
    ray they meet first (inf for a segment through the ray's origin)."""
    edge = end - start
    offset = start - origin
    denominator = direction[:, 0] * edge[:, 1] - direction[:, 1] * edge[:, 0]
    scale = np.hypot(edge[:, 0], edge[:, 1])
    parallel = np.abs(denominator) <= 1e-12 * scale
    safe = np.where(parallel, 1.0, denominator)
    across = (offset[:, 0] * edge[:, 1] - offset[:, 1] * edge[:, 0]) / safe
    # a segment along the ray (they meet, so it is collinear): its nearer end
    along = np.minimum(
        offset[:, 0] * direction[:, 0] + offset[:, 1] * direction[:, 1],
        (end - origin)[:, 0] * direction[:, 0] + (end - origin)[:, 1] * direction[:, 1],
    )
    distance = np.where(parallel, along, across)
    through = np.all(start == origin, axis=1) | np.all(end == origin, axis=1)
    return np.where(through | (distance <= 0.0), np.inf, distance)
