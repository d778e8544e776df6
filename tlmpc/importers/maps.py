"""Occupancy-grid maps and nav2 keepout / speed masks → a polygonal workspace and regions.

* Free space is the cells of value 0 (unknown space is *not* free), as the exact union of their
  squares (:mod:`tlmpc.importers.polygonize`).
* ``radius`` erodes free space by the robot's radius (configuration space of a disc robot).
* The workspace is the free piece containing ``start`` (else the largest); its outer ring is
  the boundary, its inner rings the holes; holes smaller than ``min_area`` are filled (specks).
* Rings are simplified within ``tolerance`` (default: one cell), never moving the boundary by
  more than that.
* A keepout mask's occupied cells (value 100) and a speed mask's limited cells (values 1..100)
  become regions ``keepout_1``, ``keepout_2``, ... and ``speed_<value>_<k>``, with groups
  ``keepout`` and ``speed_<value>`` naming all the pieces.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from shapely.geometry import Point as ShapelyPoint
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry

from tlmpc.errors import UsageError, error
from tlmpc.importers.occupancy import FREE, OCCUPIED, OccupancyGrid, read_map
from tlmpc.importers.polygonize import (
    cells_to_geometry,
    drop_small_holes,
    erode,
    polygons,
    simplify,
    to_world,
)

Point = tuple[float, float]
Ring = tuple[Point, ...]

#: Default speck threshold, in cells: obstacle specks and region pieces smaller are dropped.
DEFAULT_MIN_CELLS = 4.0


@dataclass(frozen=True, slots=True, kw_only=True)
class ImportSettings:
    """How a map becomes polygons (every length in map units, metres for ROS maps)."""

    radius: float = 0.0
    tolerance: float | None = None  # default: one cell
    min_area: float | None = None  # default: DEFAULT_MIN_CELLS cells
    start: Point | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class ImportedMap:
    """A workspace and regions read from a map and its masks."""

    boundary: Ring
    holes: tuple[Ring, ...]
    regions: Mapping[str, Ring]
    groups: Mapping[str, tuple[str, ...]]
    free_cells_area: float
    workspace_area: float
    resolution: float
    tolerance: float
    source: str
    speckles_dropped: int = 0
    notes: tuple[str, ...] = field(default=())


def _ring(polygon_ring: Any) -> Ring:
    coords = list(polygon_ring.coords)[:-1]
    return tuple((float(x), float(y)) for x, y in coords)


def _fail(code: str, message: str, file: str, hint: str | None = None) -> UsageError:
    return UsageError(error(code, message, hint=hint, file=file))


def free_geometry(grid: OccupancyGrid) -> BaseGeometry:
    """World-coordinate free space (cells of value 0) of a grid."""
    return to_world(cells_to_geometry(grid.values == FREE), grid.resolution, grid.origin)


def _workspace(
    grid: OccupancyGrid, settings: ImportSettings, tolerance: float, min_area: float
) -> tuple[Polygon, int]:
    free = erode(free_geometry(grid), settings.radius)
    pieces = polygons(free)
    if not pieces:
        raise _fail(
            "M010",
            "the map has no free space"
            + (f" left after eroding by the radius {settings.radius:g}" if settings.radius else ""),
            grid.source,
            hint="free cells are those with occupancy below free_thresh; "
            "check negate, the thresholds and the radius",
        )
    chosen = None
    if settings.start is not None:
        point = ShapelyPoint(settings.start)
        chosen = next((p for p in pieces if p.covers(point)), None)
    if chosen is None:
        chosen = max(pieces, key=lambda p: p.area)
    before = len(chosen.interiors)
    filled = drop_small_holes(chosen, min_area)
    simplified = simplify(filled, tolerance)
    if simplified is None:
        raise _fail("M011", "the free space vanishes when simplified", grid.source)
    result = drop_small_holes(simplified, min_area)
    return result, before - len(result.interiors)


def _mask_regions(
    mask: OccupancyGrid,
    boundary: Polygon,
    workspace: Polygon,
    prefix: str,
    values: list[int],
    tolerance: float,
    min_area: float,
) -> dict[str, dict[str, Ring]]:
    """Per value, the pieces of the mask with that value, clipped to the boundary ring."""
    found: dict[str, dict[str, Ring]] = {}
    for value in values:
        group = prefix if prefix == "keepout" else f"{prefix}_{value}"
        cells = to_world(cells_to_geometry(mask.values == value), mask.resolution, mask.origin)
        pieces: list[Polygon] = []
        for piece in polygons(cells):
            if piece.area < min_area:
                continue
            smooth = simplify(Polygon(piece.exterior), tolerance)
            if smooth is None:
                continue
            for clipped in polygons(smooth.intersection(boundary)):
                outer = Polygon(clipped.exterior)
                if outer.area >= min_area and outer.intersection(workspace).area > 0.0:
                    pieces.append(outer)
        pieces.sort(key=lambda p: (-p.area, p.bounds))
        if pieces:
            found[group] = {f"{group}_{k}": _ring(p.exterior) for k, p in enumerate(pieces, 1)}
    return found


def import_map(
    map_path: Path,
    settings: ImportSettings = ImportSettings(),
    *,
    keepout: Path | None = None,
    speed: Path | None = None,
) -> ImportedMap:
    """Read a map (and masks) and build the workspace and regions."""
    grid = read_map(map_path)
    if settings.radius < 0:
        raise _fail(
            "M012", f"the radius must not be negative, got {settings.radius:g}", str(map_path)
        )
    tolerance = grid.resolution if settings.tolerance is None else settings.tolerance
    min_area = (
        DEFAULT_MIN_CELLS * grid.cell_area() if settings.min_area is None else settings.min_area
    )
    if tolerance < 0 or min_area < 0:
        raise _fail("M012", "tolerance and min_area must not be negative", str(map_path))
    workspace, dropped = _workspace(grid, settings, tolerance, min_area)
    boundary = Polygon(workspace.exterior)
    regions: dict[str, Ring] = {}
    groups: dict[str, tuple[str, ...]] = {}
    for prefix, path in (("keepout", keepout), ("speed", speed)):
        if path is None:
            continue
        mask = read_map(path)
        if mask.shape != grid.shape or mask.resolution != grid.resolution:
            raise _fail(
                "M013",
                f"the mask is {mask.shape[1]}x{mask.shape[0]} cells at {mask.resolution:g}, "
                f"the map {grid.shape[1]}x{grid.shape[0]} at {grid.resolution:g}",
                str(path),
                hint="a mask must have the map's size, resolution and origin",
            )
        if prefix == "keepout":
            values = [OCCUPIED]
        else:
            present = np.unique(mask.values)
            values = [int(v) for v in present if 0 < v <= OCCUPIED]
        for group, members in _mask_regions(
            mask, boundary, workspace, prefix, values, tolerance, min_area
        ).items():
            regions.update(members)
            groups[group] = tuple(members)
    free_cells = float(np.count_nonzero(grid.values == FREE)) * grid.cell_area()
    return ImportedMap(
        boundary=_ring(workspace.exterior),
        holes=tuple(_ring(r) for r in workspace.interiors),
        regions=regions,
        groups=groups,
        free_cells_area=free_cells,
        workspace_area=float(workspace.area),
        resolution=grid.resolution,
        tolerance=tolerance,
        source=str(map_path),
        speckles_dropped=dropped,
    )
