"""The snapping grid of a mission, in pure Python (``tlmpc check`` answers from it without
numpy or shapely when every written coordinate lies on the grid, the usual case)."""

from __future__ import annotations

import math

from tlmpc.mission.model import Mission

#: Snapping grid, relative to the workspace's extent: closer features are merged.
GRID = 1e-9

#: A coordinate within this fraction of a grid step of a grid point lies on the grid.
ON_GRID = 1e-6


def grid_size(mission: Mission) -> float:
    """The snapping grid: a power of ten near a billionth of the workspace's extent.

    A power of ten keeps decimal coordinates (the ones users write) exactly where they are.
    """
    xs = [x for piece in mission.workspace.pieces for x, _ in piece.boundary]
    ys = [y for piece in mission.workspace.pieces for _, y in piece.boundary]
    extent = max(max(xs) - min(xs), max(ys) - min(ys))
    return float(10.0 ** math.floor(math.log10(extent * GRID)))


def off_grid(value: float, grid: float) -> bool:
    """True when ``value`` is not on the grid (the rule snapping applies)."""
    scaled = value / grid
    return abs(scaled - round(scaled)) > ON_GRID


def features_on_grid(mission: Mission) -> bool:
    """True when every region and hole vertex lies on the grid: snapping moves nothing, so
    nothing can be reshaped (the sub-grid check has nothing to examine)."""
    grid = grid_size(mission)
    polygons = [r.polygon for r in mission.regions] + list(mission.workspace.holes)
    return not any(off_grid(c, grid) for polygon in polygons for point in polygon for c in point)
