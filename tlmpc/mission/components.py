"""Geometry checks of a workspace with several pieces of free space (``workspace.components``).

Each piece is a boundary minus its own holes; pieces must not overlap nor share an edge (they
may touch at points), a
piece may sit inside another's hole (a free pocket enclosed by an obstacle), and regions and the
start are checked against the union of the pieces' free space.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import shapely
from shapely.geometry import Point as ShapelyPoint

from tlmpc.base.errors import Diagnostic, error
from tlmpc.mission.holes import obstacle
from tlmpc.mission.shapes import AREA_TOLERANCE, CheckedShape, shapely_polygon
from tlmpc.mission.yamlpos import Path, json_path

Locate = Callable[[Path], tuple[int, int]]
Piece = tuple[CheckedShape, Sequence[CheckedShape]]


def _label(index: int) -> str:
    return "the main piece (workspace.boundary)" if index == 0 else f"component {index - 1}"


def check_pieces(
    pieces: Sequence[Piece],
    regions: dict[str, CheckedShape],
    start: tuple[float, float] | None,
    start_path: Path,
    file: str,
    locate: Locate,
) -> list[Diagnostic]:
    """Containment, overlap, region and start checks over every piece of free space.

    ``pieces[0]`` is the main piece (``workspace.boundary`` and ``workspace.holes``).
    """
    problems: list[Diagnostic] = []

    def at(path: Path, code: str, message: str, hint: str) -> Diagnostic:
        line, col = locate(path)
        return error(code, message, hint=hint, file=file, line=line, col=col, path=json_path(path))

    free = []
    for index, (boundary, holes) in enumerate(pieces):
        outer = shapely_polygon(boundary)
        shapely.prepare(outer)
        for number, hole in enumerate(holes):
            if not outer.covers(shapely_polygon(hole)):
                problems.append(
                    at(
                        hole.path,
                        "G005",
                        f"hole {number} of {_label(index)} extends outside its boundary",
                        "holes must lie inside the boundary of their own piece; clip the hole",
                    )
                )
        cut = obstacle([shapely_polygon(h) for h in holes])
        free.append(outer.difference(cut) if cut is not None else outer)
    tree = shapely.STRtree(free)
    left, right = tree.query(free, predicate="intersects")
    reported: set[int] = set()
    for i, j in zip(left.tolist(), right.tolist(), strict=True):
        if i >= j or j in reported:
            continue
        shared = free[i].intersection(free[j]).area
        scale = min(free[i].area, free[j].area)
        if not (shared > AREA_TOLERANCE * max(scale, 1e-300) and shared > 0):
            # not overlapping: touching at points is fine, along an edge it is one piece
            edge = free[i].boundary.intersection(free[j].boundary).length
            if edge > 0:
                reported.add(j)
                problems.append(
                    at(
                        pieces[j][0].path,
                        "M101",
                        f"{_label(j)} shares an edge with {_label(i)} "
                        f"({edge:.6g} long): the robot could cross it",
                        "pieces may touch only at points; join pieces that share an edge "
                        "into one boundary",
                    )
                )
            continue
        reported.add(j)
        problems.append(
            at(
                pieces[j][0].path,
                "M100",
                f"the free space of {_label(j)} overlaps that of {_label(i)} "
                f"(by {shared:.6g} square units)",
                "workspace components are disjoint pieces of free space; a component may "
                "lie inside another's hole, or touch it, but not overlap its free space",
            )
        )
    union = shapely.union_all(free)
    shapely.prepare(union)
    outers = shapely.union_all([shapely_polygon(boundary) for boundary, _ in pieces])
    shapely.prepare(outers)
    for name, region in regions.items():
        # a sliver of rounding (world coordinates of a map's cells) is not "outside"
        polygon = shapely_polygon(region)
        if not outers.covers(polygon) and (
            polygon.difference(outers).area > AREA_TOLERANCE * polygon.area
        ):
            problems.append(
                at(
                    region.path,
                    "G007",
                    f"region {name!r} extends outside the workspace boundary",
                    "regions must lie inside the boundary of a workspace piece; clip the region",
                )
            )
        elif polygon.intersection(union).area <= AREA_TOLERANCE * polygon.area:
            problems.append(
                at(
                    region.path,
                    "G008",
                    f"region {name!r} lies entirely inside holes, so the robot can never be in it",
                    "move the region or shrink the holes",
                )
            )
    if start is not None:
        point = ShapelyPoint(start)
        if not union.covers(point):
            inside = bool(np.any(shapely.covers([shapely_polygon(b) for b, _ in pieces], point)))
            problems.append(
                at(
                    start_path,
                    "G010" if inside else "G009",
                    f"the start point ({start[0]:g}, {start[1]:g}) is "
                    + ("inside a hole" if inside else "outside the workspace boundary"),
                    "the robot must start in the free workspace",
                )
            )
    return problems
