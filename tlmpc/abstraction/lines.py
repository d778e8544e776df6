"""The lines of the convex cells' mesh: every side of the map's linework extended across it.

Each straight side of the free space's rings and of the regions' boundaries inside it is
extended both ways to a full line, clipped to the free space. In the arrangement of these
lines every face is convex (a reflex corner of a face would need a side to end there, but
every side goes on straight), and two faces that share a side share all of it (a vertex on
it is where another line crosses, and that line bounds both faces): a cell move between two
faces leaves by a whole side (:mod:`tlmpc.planning.cells`). The arrangement grows with the
square of the number of sides, so it is built only up to :data:`MAX_SIDES` of them.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import shapely

#: The most sides extended (their arrangement has up to about sides^2 / 2 faces).
MAX_SIDES = 120


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
