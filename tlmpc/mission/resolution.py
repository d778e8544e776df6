"""Features below the snapping grid: refused, so that planning and verifying see one geometry.

The mesh is built on coordinates snap-rounded to a grid of about a billionth of the map's
extent (:func:`tlmpc.abstraction.triangulate.grid_size`), but the verifier checks trajectories
against the regions and holes as written.  The two agree to within the grid unless snapping
changes a feature's *shape*: a region or hole thinner than the grid collapses (a forbidden
strip would vanish and the planner walk through it), or two features closer than the grid
come to touch or overlap (a gap of free space between them disappears).  Those missions are
refused with a located diagnostic (G030, G031) instead of giving a plan the verifier rejects.

Only polygons that snapping moves are examined (written in decimals, the usual case, they lie
on the grid already), so maps with thousands of rooms pay nothing.  This module imports only
shapely and numpy: ``tlmpc check`` runs it too, without the triangulation's libraries.
"""

from __future__ import annotations

from collections.abc import Sequence
from itertools import chain
from typing import Any

import numpy as np
import shapely

from tlmpc.base.errors import Diagnostic, InvalidInputError, error
from tlmpc.mission.grid import GRID, ON_GRID, grid_size
from tlmpc.mission.model import Mission, Polygon
from tlmpc.mission.placement import placed
from tlmpc.mission.yamlpos import json_path

#: A snapped feature must lie within this many grid steps of the written one, and conversely
#: (snap-rounding moves every point by at most half a diagonal step).
SHIFT_ALLOWED = 1.5


def _off_grid(polygons: Sequence[Polygon], grid: float) -> list[int]:
    """Indices of the polygons with a vertex off the grid (vectorised over all of them)."""
    if not polygons:
        return []
    # One array from all the points at once (an array per polygon costs more than the test).
    coords = np.array(
        list(chain.from_iterable(chain.from_iterable(polygons))), dtype=np.float64
    ).reshape(-1, 2)
    owner = np.repeat(np.arange(len(polygons)), [len(p) for p in polygons])
    scaled = coords / grid
    off = np.abs(scaled - np.round(scaled)).max(axis=1) > ON_GRID
    moved = np.zeros(len(polygons), dtype=bool)
    np.logical_or.at(moved, owner, off)
    return np.flatnonzero(moved).tolist()


def _lost(raw: Any, snapped: Any, reach: float) -> bool:
    """True when snapping changed the feature's shape, not only moved it by under ``reach``:
    it collapsed, or a corner of either outline lies farther than ``reach`` from the other
    outline (a thin arm that vanished leaves its tip behind).  Point-to-outline distances
    only, no overlay: exact enough at the grid's scale."""
    if shapely.is_empty(snapped) or shapely.area(snapped) <= 0.0:
        return True
    away = shapely.distance(shapely.points(shapely.get_coordinates(raw)), shapely.boundary(snapped))
    grown = shapely.distance(
        shapely.points(shapely.get_coordinates(snapped)), shapely.boundary(raw)
    )
    return bool(max(float(np.max(away)), float(np.max(grown))) > reach)


def subgrid_problems(mission: Mission) -> list[Diagnostic]:
    """G030 for every region or hole that snapping reshapes, G031 for every pair of them that
    snapping makes touch (or overlap) although they are apart as written."""
    grid = grid_size(mission)
    reach = SHIFT_ALLOWED * grid
    named: list[tuple[str, tuple[str | int, ...], Polygon]] = [
        (f"region {r.name!r}", ("regions", r.name), r.polygon) for r in mission.regions
    ]
    named += [
        (f"hole {i + 1}", ("workspace", "holes", i), h)
        for i, h in enumerate(mission.workspace.holes)
    ]
    moved = _off_grid([p for _, _, p in named], grid)
    if not moved:
        return []
    raw = [shapely.Polygon(p) for _, _, p in named]
    snapped = {i: shapely.set_precision(raw[i], grid) for i in moved}
    problems: list[tuple[str, tuple[str | int, ...], str]] = []
    for index in moved:
        if _lost(raw[index], snapped[index], reach):
            name, path, _ = named[index]
            problems.append(
                (
                    "G030",
                    path,
                    f"{name} is thinner than the snapping grid ({grid:g}) somewhere: the mesh "
                    "would not have the shape written here",
                )
            )
    tree = shapely.STRtree(raw)
    for index in moved:
        for other in tree.query(shapely.buffer(raw[index], reach)).tolist():
            if other == index or (other in snapped and other < index):
                continue
            apart = not shapely.intersects(raw[index], raw[other])
            theirs = snapped.get(other, raw[other])
            if apart and shapely.intersects(snapped[index], theirs):
                gap = shapely.distance(raw[index], raw[other])
                problems.append(
                    (
                        "G031",
                        named[index][1],
                        f"{named[index][0]} and {named[other][0]} are {gap:.3g} apart, below "
                        f"the snapping grid ({grid:g}): the mesh would make them touch",
                    )
                )
    hint = (
        "make the feature wider than the grid (about a billionth of the map's size) "
        "or remove it; features are never silently dropped"
    )
    found = [
        error(code, message, hint=hint, file=mission.source, path=json_path(path))
        for code, path, message in problems
    ]
    return list(placed(found, mission.source))


__all__ = ["GRID", "grid_size", "refuse_subgrid_features", "subgrid_problems"]


def refuse_subgrid_features(mission: Mission) -> None:
    """Raise :class:`InvalidInputError` (exit 1) when snapping would reshape the map."""
    problems = subgrid_problems(mission)
    if problems:
        raise InvalidInputError(problems)
