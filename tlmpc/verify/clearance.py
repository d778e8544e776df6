"""Clearance and depth a trajectory achieved, measured with shapely on the trace alone.

* **obstacles**: the least distance from the path (its segments) to the holes and the
  boundary, minus the body radius: how far the robot's body stayed from every obstacle;
* **forbidden**: the least distance from the path to the regions the task only ever avoids
  (negative in its negation normal form), each and overall (0 when the path touches one);
* **depth**: for each region the task only ever asks for (positive) that the path enters,
  the deepest a sample of the path got inside it (distance to the region's boundary), and
  the depth that region allows at most (its inradius), so ``min(margin, inradius / 2)`` is
  what a planner can promise.

Nothing here knows the planner: the verifier's own trace input and the task's polarity.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import shapely
from shapely.ops import polylabel

from tlmpc.base.errors import Diagnostic
from tlmpc.ltl.polarity import polarities
from tlmpc.mission.body import MARGIN_PATH
from tlmpc.verify.trace_input import TraceInput


@dataclass(frozen=True, slots=True, kw_only=True)
class Depth:
    """How deep the path went into one goal region, and how deep the region allows."""

    achieved: float
    inradius: float
    position: tuple[float, float]


@dataclass(frozen=True, slots=True, kw_only=True)
class Clearance:
    """What :func:`measure` found (distances in map units; None where nothing applies)."""

    radius: float
    obstacles: float | None
    obstacle_position: tuple[float, float] | None
    forbidden: Mapping[str, float] = field(default_factory=dict)
    forbidden_positions: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    depth: Mapping[str, Depth] = field(default_factory=dict)

    @property
    def overall(self) -> float | None:
        """The least of the obstacle and forbidden-region clearances."""
        values = [v for v in (self.obstacles, *self.forbidden.values()) if v is not None]
        return min(values) if values else None

    def to_json(self, margin: float) -> dict[str, Any]:
        """The ``clearance`` object of ``summary.json``."""
        return {
            "margin": margin,
            "radius": self.radius,
            "achieved": self.overall,
            "obstacles": self.obstacles,
            "forbidden": dict(self.forbidden),
            "depth": {
                name: {"achieved": d.achieved, "inradius": d.inradius}
                for name, d in self.depth.items()
            },
        }


def _segments(points: np.ndarray[Any, Any]) -> Any:
    if len(points) == 1:
        return shapely.points(points)
    return shapely.linestrings(np.stack([points[:-1], points[1:]], axis=1))


def _closest(points: np.ndarray[Any, Any], segment: int, target: Any) -> tuple[float, float]:
    # only the one segment: building every segment again costs as much as the measurement
    piece = _segments(points[segment : segment + 2])[0]
    a, _ = shapely.shortest_line(piece, target).coords
    return (float(a[0]), float(a[1]))


def inradius(polygon: Any) -> float:
    """The radius of the largest disc inside ``polygon`` (to a thousandth of its size)."""
    minx, miny, maxx, maxy = polygon.bounds
    pole = polylabel(polygon, tolerance=1e-3 * max(maxx - minx, maxy - miny))
    return float(polygon.boundary.distance(pole))


def free_space(trace: TraceInput) -> Any:
    """The trace's free space: every workspace piece (boundary minus holes), united; None
    without a workspace."""
    if trace.boundary_polygon is None:
        return None
    pieces = [(trace.boundary_polygon, trace.holes), *trace.components]
    free_pieces = []
    for boundary, holes in pieces:
        free = shapely.Polygon(boundary)
        if holes:
            free = free.difference(shapely.union_all([shapely.Polygon(h) for h in holes]))
        free_pieces.append(free)
    free = free_pieces[0] if len(free_pieces) == 1 else shapely.union_all(free_pieces)
    shapely.prepare(free)
    return free


def measure(trace: TraceInput) -> Clearance:
    """Clearance from obstacles and forbidden regions, and depth into goals, of ``trace``."""
    points = np.asarray(trace.points, dtype=np.float64)
    segments = _segments(points)
    obstacles: float | None = None
    obstacle_position: tuple[float, float] | None = None
    free = free_space(trace)
    if free is not None:
        # every ring of the free space (all workspace pieces, their holes): a path in a second
        # piece is measured against that piece's walls, as the verifier measures it
        walls = list(shapely.get_parts(shapely.boundary(free)))
        tree = shapely.STRtree(walls)
        (index, wall), distance = tree.query_nearest(
            segments, return_distance=True, all_matches=False
        )
        worst = int(np.argmin(distance))
        obstacles = float(distance[worst]) - trace.radius
        obstacle_position = _closest(points, int(index[worst]), walls[int(wall[worst])])
    signs = polarities(trace.formula)
    forbidden: dict[str, float] = {}
    forbidden_positions: dict[str, tuple[float, float]] = {}
    depth: dict[str, Depth] = {}
    for name, ring in trace.regions.items():
        sign = signs.get(name)
        if sign not in ("negative", "positive"):
            continue
        region = shapely.Polygon(ring)
        if sign == "negative":
            distance = np.asarray(shapely.distance(region, segments), dtype=np.float64)
            worst = int(np.argmin(distance))
            forbidden[name] = float(distance[worst])
            forbidden_positions[name] = _closest(points, worst, region)
        else:
            # only the samples in the region's bounding box can be covered by it: a shapely
            # point for each of them, not for every sample of a long path once per region
            minx, miny, maxx, maxy = region.bounds
            boxed = points[
                (points[:, 0] >= minx)
                & (points[:, 0] <= maxx)
                & (points[:, 1] >= miny)
                & (points[:, 1] <= maxy)
            ]
            inside = np.asarray(shapely.covers(region, shapely.points(boxed)), dtype=bool)
            if not inside.any():
                continue
            candidates = boxed[inside]
            deep = np.asarray(
                shapely.distance(region.boundary, shapely.points(candidates)), dtype=np.float64
            )
            best = int(np.argmax(deep))
            depth[name] = Depth(
                achieved=float(deep[best]),
                inradius=inradius(region),
                position=(float(candidates[best][0]), float(candidates[best][1])),
            )
    return Clearance(
        radius=trace.radius,
        obstacles=obstacles,
        obstacle_position=obstacle_position,
        forbidden=forbidden,
        forbidden_positions=forbidden_positions,
        depth=depth,
    )


def margin_warnings(clearance: Clearance, margin: float, file: str | None) -> list[Diagnostic]:
    """R006 where the path came closer than ``margin`` to an obstacle or forbidden region,
    R007 where it went less deep into a goal than ``min(margin, inradius / 2)``."""
    if margin <= 0.0:
        return []
    tolerance = 1e-9 * max(1.0, margin)
    found: list[Diagnostic] = []
    near: list[tuple[float, str, tuple[float, float]]] = []
    if clearance.obstacles is not None and clearance.obstacle_position is not None:
        near.append((clearance.obstacles, "an obstacle", clearance.obstacle_position))
    for name, value in clearance.forbidden.items():
        near.append((value, f"region {name!r}", clearance.forbidden_positions[name]))
    for value, what, (x, y) in sorted(near):
        if value >= margin - tolerance:
            continue
        body = " (beyond the body)" if what == "an obstacle" and clearance.radius > 0 else ""
        found.append(
            Diagnostic(
                code="R006",
                severity="warning",
                message=f"the margin {margin:g} could not be kept: the path passes "
                f"{max(value, 0.0):.4g}{body} from {what} near ({x:.6g}, {y:.6g})",
                hint="the geometry leaves no wider way there; widen it or lower options.margin",
                file=file,
                path=MARGIN_PATH,
            )
        )
    for name, depth in clearance.depth.items():
        wanted = min(margin, depth.inradius / 2.0)
        if depth.achieved >= wanted - tolerance:
            continue
        x, y = depth.position
        found.append(
            Diagnostic(
                code="R007",
                severity="warning",
                message=f"the path goes only {depth.achieved:.4g} deep into region {name!r} "
                f"(at ({x:.6g}, {y:.6g})), less than the {wanted:.4g} asked",
                hint="its deep part is out of reach with the margin; lower options.margin",
                file=file,
                path=MARGIN_PATH,
            )
        )
    return found
