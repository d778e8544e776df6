"""Observation-preserving constrained Delaunay triangulation of a mission's workspace.

The free space (boundary minus holes) and every region boundary clipped to it are noded with
shapely (crossing boundaries of overlapping regions meet at a vertex), then handed to
Shewchuk's Triangle as a planar straight-line graph.  Because every region boundary is a
chain of constraint segments, each triangle lies wholly inside or wholly outside each region.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import shapely
import triangle
from shapely.geometry import MultiPolygon
from shapely.geometry import Polygon as ShapelyPolygon

from tlmpc.errors import InvalidInputError, error
from tlmpc.mission.model import Mission

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: Vertices closer than this fraction of the workspace size are merged before Triangle runs.
SNAP = 1e-10


def free_space(mission: Mission) -> ShapelyPolygon | MultiPolygon:
    """The workspace boundary minus the holes."""
    boundary = ShapelyPolygon(mission.workspace.boundary)
    if not mission.workspace.holes:
        return shapely.normalize(boundary)
    holes = shapely.union_all([ShapelyPolygon(h) for h in mission.workspace.holes])
    free = boundary.difference(holes)
    if free.is_empty:
        raise InvalidInputError(
            error(
                "A001",
                "the holes cover the whole workspace: there is no free space",
                hint="shrink the holes",
                file=mission.source,
            )
        )
    return free


def _polygons(geometry: Any) -> list[ShapelyPolygon]:
    if isinstance(geometry, ShapelyPolygon):
        return [geometry] if not geometry.is_empty else []
    if hasattr(geometry, "geoms"):
        result: list[ShapelyPolygon] = []
        for part in geometry.geoms:
            result.extend(_polygons(part))
        return result
    return []


def _rings(polygon: ShapelyPolygon) -> list[Any]:
    return [polygon.exterior, *polygon.interiors]


def _segments_of(lines: Sequence[Any]) -> FloatArray:
    """All straight segments of the given linework as an (s, 2, 2) array."""
    coords = shapely.get_coordinates(lines, return_index=True)
    points, owner = coords
    if len(points) < 2:
        return np.zeros((0, 2, 2))
    same = owner[1:] == owner[:-1]
    starts = points[:-1][same]
    ends = points[1:][same]
    return np.stack([starts, ends], axis=1)


def _needs_noding(free_rings: list[Any], region_polygons: list[ShapelyPolygon]) -> bool:
    """True when some region boundary crosses or touches another ring (noding required)."""
    rings = [*free_rings, *(p.exterior for p in region_polygons)]
    if len(rings) <= 1:
        return False
    tree = shapely.STRtree(rings)
    pairs = tree.query(rings, predicate="intersects")
    return bool(np.any(pairs[0] != pairs[1]))


def pslg(mission: Mission) -> tuple[FloatArray, IntArray, FloatArray]:
    """The planar straight-line graph: vertices, segments (index pairs), hole seed points."""
    free = free_space(mission)
    parts = _polygons(free)
    free_rings = [ring for part in parts for ring in _rings(part)]
    regions = [ShapelyPolygon(r.polygon) for r in mission.regions]
    region_lines: list[Any] = []
    if _needs_noding(free_rings, regions):
        clipped = [shapely.intersection(shapely.boundary(r), free) for r in regions]
        region_lines = [c for c in clipped if not c.is_empty]
        linework = shapely.node(shapely.union_all([*free_rings, *region_lines]))
        segments = _segments_of(list(shapely.get_parts(linework)))
    else:
        segments = _segments_of([*free_rings, *(r.exterior for r in regions)])
    minx, miny, maxx, maxy = free.bounds
    scale = max(maxx - minx, maxy - miny)
    step = scale * SNAP
    flat = segments.reshape(-1, 2)
    keys = np.round((flat - np.array([minx, miny])) / step).astype(np.int64)
    unique_keys, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    vertices = flat[first]
    edges = inverse.reshape(-1, 2)
    edges = edges[edges[:, 0] != edges[:, 1]]
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    seeds = []
    free_union = shapely.union_all(parts)
    for part in parts:
        for interior in part.interiors:
            inside = ShapelyPolygon(interior).difference(free_union)
            if not inside.is_empty:
                point = inside.representative_point()
                seeds.append((point.x, point.y))
    del unique_keys
    return vertices.astype(np.float64), edges.astype(np.int64), np.array(seeds, dtype=np.float64)


def triangulate(
    mission: Mission,
) -> tuple[FloatArray, IntArray, IntArray]:
    """Vertices, counter-clockwise triangles and neighbours of the constrained triangulation."""
    vertices, segments, seeds = pslg(mission)
    options = "pznQ"
    if mission.options.min_angle is not None and mission.options.min_angle > 0:
        options += f"q{mission.options.min_angle:g}"
    if mission.options.max_area is not None:
        options += f"a{mission.options.max_area:.17g}"
    data: dict[str, Any] = {"vertices": vertices, "segments": segments}
    if len(seeds):
        data["holes"] = seeds
    result = triangle.triangulate(data, options)
    points = np.asarray(result["vertices"], dtype=np.float64)
    triangles = np.asarray(result["triangles"], dtype=np.int64)
    neighbors = np.asarray(result["neighbors"], dtype=np.int64)
    return points, triangles, neighbors
