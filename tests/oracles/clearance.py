"""An independent clearance checker: exact segment distances on the raw geometry.

Given the obstacles as the test wrote them (every piece's outer ring, every hole), the
clearance of a polyline is the least exact distance (shapely's segment-segment distance)
from any of its segments to any obstacle ring.  Nothing here comes from tlmpc: not its
configuration space, not its trace parsing.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import shapely

Ring = Sequence[tuple[float, float]]


def obstacle_rings(pieces: Sequence[tuple[Ring, Sequence[Ring]]]) -> list[shapely.LineString]:
    """The rings bounding the free space: each piece's outer ring and its holes."""
    rings = []
    for outer, holes in pieces:
        for ring in (outer, *holes):
            closed = [*ring, ring[0]]
            rings.append(shapely.LineString(closed))
    return rings


def path_clearance(points: Sequence[Sequence[float]], rings: Sequence[shapely.LineString]) -> float:
    """The least exact distance from the polyline through ``points`` to the rings."""
    xy = np.asarray(points, dtype=float)
    if len(xy) == 1:
        parts = [shapely.Point(xy[0])]
    else:
        parts = [shapely.LineString([a, b]) for a, b in itertools.pairwise(xy)]
    return min(float(shapely.distance(ring, part)) for ring in rings for part in parts)


def inside_free(point: tuple[float, float], pieces: Sequence[tuple[Ring, Sequence[Ring]]]) -> bool:
    """True when ``point`` is in some piece and in none of its holes (closed sets)."""
    where = shapely.Point(point)
    for outer, holes in pieces:
        if shapely.Polygon(outer).covers(where) and not any(
            shapely.Polygon(h).contains(where) for h in holes
        ):
            return True
    return False
