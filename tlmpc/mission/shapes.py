"""A checked shape: the type the mission's geometry checks pass between them.

Its points passed their own checks; its shapely polygon is built on first use only, so that
``tlmpc check`` of a plain mission imports neither shapely nor numpy.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from tlmpc.mission.model import Polygon
from tlmpc.mission.yamlpos import Path

if TYPE_CHECKING:
    from shapely.geometry import Polygon as ShapelyPolygon

#: Relative tolerance for "zero area" (relative to the squared size of the shape).
AREA_TOLERANCE = 1e-12


@dataclass(frozen=True, slots=True)
class CheckedShape:
    """A shape that passed its own checks, as points and (built on first use) a shapely polygon."""

    points: Polygon
    polygon: ShapelyPolygon | None
    path: Path


def shapely_polygon(shape: CheckedShape) -> ShapelyPolygon:
    """The shape's shapely polygon, built once when a check first needs it."""
    if shape.polygon is None:
        import numpy as np
        import shapely

        # shapely.polygons on an array is linear in the vertices, unlike a list of tuples
        object.__setattr__(shape, "polygon", shapely.polygons(np.asarray(shape.points, float)))
    assert shape.polygon is not None
    return shape.polygon
