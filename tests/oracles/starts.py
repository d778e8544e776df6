"""The triangles holding a start point, and the edges through it, decided with shapely.

Independent of tlmpc's planner (which decides the same in rational arithmetic): a triangle
holds the start when its closed polygon intersects the point, and an edge is *blocked* for the
first move when its closed segment does (leaving through it at t = 0 never enters the
triangle).
"""

from __future__ import annotations

from collections.abc import Sequence

import shapely

from tlmpc.abstraction.model import Abstraction


def start_triangles(abstraction: Abstraction, point: Sequence[float]) -> dict[int, set[int]]:
    """Triangle -> its edges (opposite-vertex numbering) that contain ``point``."""
    probe = shapely.Point(float(point[0]), float(point[1]))
    found: dict[int, set[int]] = {}
    for t in range(abstraction.num_triangles):
        corners = [tuple(map(float, c)) for c in abstraction.vertices[abstraction.triangles[t]]]
        if not shapely.intersects(shapely.Polygon(corners), probe):
            continue
        found[t] = {
            i
            for i in range(3)
            if shapely.intersects(
                shapely.LineString([corners[(i + 1) % 3], corners[(i + 2) % 3]]), probe
            )
        }
    return found
