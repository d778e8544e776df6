"""Two oracles for the corner push max over unit u of min_k a_k·u (unit normals a_k).

* :func:`arc_push`, by definition of the arc: the normals' angles sorted, the arc holding them
  all is the circle less its widest gap between neighbours, and for an arc of s < 180 degrees
  the best u is the bisector of its ends (cos(s / 2)); from 180 degrees on no u pushes along
  every normal (0 here, the value a vertex's row admits). No normal: 1.
* :func:`sampled_push`, brute force over directions: min_k a_k·u at ``count`` directions
  evenly round the circle, the largest of them. Each a_k·u is 1-Lipschitz in u's angle, so the
  true maximum is at most ``pi / count`` above it.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np

Vector = tuple[float, float]


def arc_push(normals: Sequence[Vector]) -> float:
    """The corner push of ``normals`` from the arc that holds them (at least 0)."""
    if not normals:
        return 1.0
    angles = sorted(math.atan2(y, x) for x, y in normals)
    gaps = [b - a for a, b in itertools.pairwise(angles)]
    gaps.append(angles[0] + 2.0 * math.pi - angles[-1])
    spread = 2.0 * math.pi - max(gaps)
    return math.cos(spread / 2.0) if spread < math.pi else 0.0


def sampled_push(normals: Sequence[Vector], count: int = 200_000) -> float:
    """The largest min_k a_k·u over ``count`` directions u evenly round the circle."""
    if not normals:
        return 1.0
    turns = np.arange(count, dtype=np.float64) * (2.0 * math.pi / count)
    directions = np.stack([np.cos(turns), np.sin(turns)], axis=1)
    return float((directions @ np.asarray(normals, dtype=np.float64).T).min(axis=1).max())
