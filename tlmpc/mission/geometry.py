"""Geometry checks of a mission: shapes, holes, regions, start point.

Shapely decides; small plain missions (no holes, a rectangular boundary, polygons of a few
dozen vertices) are decided exactly in pure Python first (:mod:`tlmpc.mission.plain_geometry`),
so that ``tlmpc check`` of such a mission imports neither shapely nor numpy.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from itertools import chain
from typing import Any

from tlmpc.base.errors import Diagnostic, error
from tlmpc.mission import plain_geometry
from tlmpc.mission.holes import obstacle
from tlmpc.mission.model import Polygon
from tlmpc.mission.shapes import AREA_TOLERANCE, CheckedShape, shapely_polygon
from tlmpc.mission.yamlpos import Path, json_path

Locate = Callable[[Path], tuple[int, int]]

#: Point lists longer than this are checked with array operations (numpy, shapely); shorter
#: ones in pure Python first, so that a plain mission's check imports neither.
ARRAY_ABOVE = 64


def shape_points(shape: Any) -> Polygon:
    """The vertices of a shape: a point list as given, or a rectangle counter-clockwise."""
    if isinstance(shape, dict):
        x0, y0, x1, y1 = (float(v) for v in shape["rect"])
        return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
    if len(shape) > ARRAY_ABOVE:
        return tuple(map(tuple, _vertices(shape)[0].tolist()))
    points: list[tuple[float, float]] = []
    for x, y in shape:
        point = (float(x), float(y))
        if not points or points[-1] != point:
            points.append(point)
    if len(points) > 1 and points[0] == points[-1]:
        points.pop()  # a closed ring given with its first point repeated
    return tuple(points)


def _vertices(shape: Any) -> tuple[Any, Any]:
    """A point list as an n×2 array, repeats of the previous point and a closing point dropped,
    and the index in ``shape`` of each vertex kept.

    Array operations throughout: a boundary may have a million vertices.
    """
    import numpy as np

    points = np.asarray(shape, dtype=float).reshape(-1, 2)
    index = np.arange(len(points))
    if len(points) > 1:
        kept = np.concatenate(([True], np.any(points[1:] != points[:-1], axis=1)))
        points, index = points[kept], index[kept]
    if len(points) > 1 and np.array_equal(points[0], points[-1]):
        points, index = points[:-1], index[:-1]  # a closed ring given with its first point again
    return points, index


def _three_distinct(points: Any) -> bool:
    """Whether ``points`` holds three different points (linear; sorting a million is not)."""
    import numpy as np

    if len(points) < 3:
        return False
    other = np.any(points != points[0], axis=1)
    if not other.any():
        return False
    second = points[int(np.argmax(other))]
    return bool(np.any(other & np.any(points != second, axis=1)))


def _collinear_array(points: Any, size: float) -> bool:
    import numpy as np

    x0, y0 = points[0]
    dx_all = points[:, 0] - x0
    dy_all = points[:, 1] - y0
    x1, y1 = points[int(np.argmax(dx_all**2 + dy_all**2))]
    dx, dy = x1 - x0, y1 - y0
    length = float(dx * dx + dy * dy) ** 0.5
    if length == 0.0:
        return True
    return bool(np.all(np.abs(dx * dy_all - dy * dx_all) / length <= 1e-12 * size))


def _collinear(points: Polygon, size: float) -> bool:
    x0, y0 = points[0]
    x1, y1 = max(points, key=lambda p: (p[0] - x0) ** 2 + (p[1] - y0) ** 2)
    dx, dy = x1 - x0, y1 - y0
    length = (dx * dx + dy * dy) ** 0.5
    if length == 0.0:
        return True
    return all(abs(dx * (y - y0) - dy * (x - x0)) / length <= 1e-12 * size for x, y in points)


def _crossing_vertex(points: Any, reason: str) -> int | None:
    """The vertex starting the edge nearest the place ``explain_validity`` names, if any."""
    import numpy as np

    found = re.search(r"\[\s*([-+0-9.eE]+)\s+([-+0-9.eE]+)", reason)
    if found is None or len(points) < 2:
        return None
    x, y = float(found.group(1)), float(found.group(2))
    start = points
    end = np.roll(points, -1, axis=0)
    edge = end - start
    squared = np.einsum("ij,ij->i", edge, edge)
    squared[squared == 0.0] = 1.0
    t = np.clip(((x - start[:, 0]) * edge[:, 0] + (y - start[:, 1]) * edge[:, 1]) / squared, 0, 1)
    gap = np.hypot(start[:, 0] + t * edge[:, 0] - x, start[:, 1] + t * edge[:, 1] - y)
    return int(np.argmin(gap))


def check_shape(
    shape: Any, path: Path, what: str, file: str, locate: Locate
) -> tuple[CheckedShape | None, list[Diagnostic]]:
    """Validate one shape; return it when usable, with the problems found."""
    if isinstance(shape, dict):
        x0, y0, x1, y1 = map(float, shape["rect"])
        size = max(x1 - x0, y1 - y0)
        if x0 < x1 and y0 < y1 and (x1 - x0) * (y1 - y0) > AREA_TOLERANCE * size * size:
            # A proper rect is simple, valid and not collinear: skip the general checks and
            # the position (a map of 10^4 rooms is mostly rects).
            corners: Polygon = ((x0, y0), (x1, y0), (x1, y1), (x0, y1))  # as shape_points
            return CheckedShape(points=corners, polygon=None, path=path), []

    def where() -> dict[str, Any]:
        # Only a problem asks where the shape is (a lazily read file is read again for it).
        line, col = locate(path)
        return {"file": file, "line": line, "col": col, "path": json_path(path)}

    if isinstance(shape, dict):
        x0, y0, x1, y1 = (float(v) for v in shape["rect"])
        if not (x0 < x1 and y0 < y1):
            return None, [
                error(
                    "G001",
                    f"{what}: rect needs xmin < xmax and ymin < ymax, got "
                    f"[{x0:g}, {y0:g}, {x1:g}, {y1:g}]",
                    hint="write {rect: [xmin, ymin, xmax, ymax]}",
                    **where(),
                )
            ]
    elif len(shape) > ARRAY_ABOVE:
        return _check_long_shape(shape, path, what, locate, where)
    points = shape_points(shape)
    if len(set(points)) < 3:
        return None, [_too_few(what, where())]
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    size = max(max(xs) - min(xs), max(ys) - min(ys), 1e-300)
    if _collinear(points, size):
        return None, [_collinear_problem(what, where())]
    checked = CheckedShape(points=points, polygon=None, path=path)
    if (
        plain_geometry.certainly_simple(points)
        and abs(plain_geometry.shoelace_area(points)) > 2 * AREA_TOLERANCE * size * size
    ):
        return checked, []  # what shapely would say: valid, with an area well above zero
    polygon = shapely_polygon(checked)
    if not polygon.is_valid:
        from shapely.validation import explain_validity

        reason = explain_validity(polygon)
        at = _at_crossing(shape, path, reason, locate, where())
        return None, [_not_simple(what, reason, at)]
    if abs(polygon.area) <= AREA_TOLERANCE * size * size:
        return None, [_zero_area(what, where())]
    return checked, []


def _at_crossing(
    shape: Any, path: Path, reason: str, locate: Locate, where: dict[str, Any]
) -> dict[str, Any]:
    """``where`` moved to the edge ``explain_validity`` names: in a boundary of a million
    vertices, "line 3" is useless."""
    array, written = _vertices(shape)
    vertex = _crossing_vertex(array, reason)
    if vertex is None:
        return where
    at = (*path, int(written[vertex]))
    line, col = locate(at)
    return {**where, "line": line, "col": col, "path": json_path(at)}


def _check_long_shape(
    shape: Any, path: Path, what: str, locate: Locate, where: Callable[[], dict[str, Any]]
) -> tuple[CheckedShape | None, list[Diagnostic]]:
    """:func:`check_shape` of a long point list, with array operations only."""
    import shapely
    from shapely.validation import explain_validity

    array, _ = _vertices(shape)
    if not _three_distinct(array):
        return None, [_too_few(what, where())]
    polygon = shapely.polygons(array)  # linear, unlike a list
    minx, miny, maxx, maxy = polygon.bounds
    size = max(maxx - minx, maxy - miny, 1e-300)
    if _collinear_array(array, size):
        return None, [_collinear_problem(what, where())]
    if not polygon.is_valid:
        reason = explain_validity(polygon)
        at = _at_crossing(shape, path, reason, locate, where())
        return None, [_not_simple(what, reason, at)]
    if abs(polygon.area) <= AREA_TOLERANCE * size * size:
        return None, [_zero_area(what, where())]
    points = tuple(map(tuple, array.tolist()))
    return CheckedShape(points=points, polygon=polygon, path=path), []


def _too_few(what: str, where: dict[str, Any]) -> Diagnostic:
    return error(
        "G002",
        f"{what}: a polygon needs at least 3 distinct points",
        hint="list the corners as [[x, y], ...]",
        **where,
    )


def _collinear_problem(what: str, where: dict[str, Any]) -> Diagnostic:
    return error(
        "G003",
        f"{what}: the polygon has zero area",
        hint="its points are collinear; give a proper polygon",
        **where,
    )


def _zero_area(what: str, where: dict[str, Any]) -> Diagnostic:
    return error(
        "G003",
        f"{what}: the polygon has zero area",
        hint="give a polygon with a positive area",
        **where,
    )


def _not_simple(what: str, reason: str, where: dict[str, Any]) -> Diagnostic:
    return error(
        "G004",
        f"{what}: the polygon is self-intersecting or not simple ({reason})",
        hint="edges must not cross or touch; list the corners in order around the shape",
        **where,
    )


def check_layout(
    boundary: CheckedShape | None,
    holes: Sequence[CheckedShape],
    regions: dict[str, CheckedShape],
    start: tuple[float, float] | None,
    start_path: Path,
    file: str,
    locate: Locate,
    components: Sequence[tuple[CheckedShape, Sequence[CheckedShape]]] = (),
) -> list[Diagnostic]:
    """Relations between shapes: containment, the start point (hole overlaps are merged).

    With further workspace ``components``, every piece is checked by
    :func:`tlmpc.mission.components.check_pieces`.
    """
    if components and boundary is not None:
        from tlmpc.mission.components import check_pieces

        return check_pieces(
            [(boundary, holes), *components], regions, start, start_path, file, locate
        )
    problems: list[Diagnostic] = []

    def at(path: Path, code: str, message: str, hint: str) -> Diagnostic:
        line, col = locate(path)
        return error(code, message, hint=hint, file=file, line=line, col=col, path=json_path(path))

    rect = plain_geometry.axis_rectangle(boundary.points) if boundary is not None else None
    if rect is not None and not holes:
        # A rectangular workspace without holes: containment in a closed convex shape is
        # exactly "every vertex inside", decided by comparisons alone (what shapely answers);
        # first for all regions at once, at C speed (a map of 10^4 rooms), then one by one
        # only when some vertex is outside
        coordinates = list(
            chain.from_iterable(chain.from_iterable(r.points for r in regions.values()))
        )
        xs, ys = coordinates[0::2], coordinates[1::2]
        everything_inside = not coordinates or (
            rect[0] <= min(xs) and max(xs) <= rect[2] and rect[1] <= min(ys) and max(ys) <= rect[3]
        )
        one_by_one = () if everything_inside else regions.items()
        for name, region in one_by_one:
            if not plain_geometry.inside_rectangle(region.points, rect):
                problems.append(
                    at(
                        region.path,
                        "G007",
                        f"region {name!r} extends outside the workspace boundary",
                        "regions must lie inside the boundary; clip the region",
                    )
                )
        if start is not None and not plain_geometry.inside_rectangle([start], rect):
            problems.append(
                at(
                    start_path,
                    "G009",
                    f"the start point ({start[0]:g}, "
                    f"{start[1]:g}) is outside the workspace boundary",
                    "the robot must start in the free workspace",
                )
            )
        return problems
    import shapely
    from shapely.geometry import Point as ShapelyPoint

    # Near-linear on large inputs: the boundary is prepared once (an indexed edge set, so each
    # containment test is logarithmic in its vertices), and overlap tests run only on pairs a
    # spatial index reports as candidates, never on all pairs.
    hole_union = obstacle([shapely_polygon(h) for h in holes])
    if hole_union is not None:
        shapely.prepare(hole_union)
    if boundary is not None:
        outer = shapely_polygon(boundary)
        shapely.prepare(outer)
        for index, hole in enumerate(holes):
            if not outer.covers(shapely_polygon(hole)):
                problems.append(
                    at(
                        hole.path,
                        "G005",
                        f"hole {index} extends outside the workspace boundary",
                        "holes must lie inside the boundary; clip the hole",
                    )
                )
        for name, region in regions.items():
            if not outer.covers(shapely_polygon(region)):
                problems.append(
                    at(
                        region.path,
                        "G007",
                        f"region {name!r} extends outside the workspace boundary",
                        "regions must lie inside the boundary; clip the region",
                    )
                )
    # overlapping holes are merged later, with a note (tlmpc.mission.holes); what they
    # enclose is part of the obstacle already
    if hole_union is not None:
        for name, region in regions.items():
            if not hole_union.intersects(shapely_polygon(region)):
                continue
            free = shapely_polygon(region).difference(hole_union)
            if free.area <= AREA_TOLERANCE * shapely_polygon(region).area:
                problems.append(
                    at(
                        region.path,
                        "G008",
                        f"region {name!r} lies entirely inside "
                        "holes, so the robot can never be in it",
                        "move the region or shrink the holes",
                    )
                )
    if start is not None:
        point = ShapelyPoint(start)
        if boundary is not None and not shapely_polygon(boundary).covers(point):
            problems.append(
                at(
                    start_path,
                    "G009",
                    f"the start point ({start[0]:g}, "
                    f"{start[1]:g}) is outside the workspace boundary",
                    "the robot must start in the free workspace",
                )
            )
        elif hole_union is not None and hole_union.covers(point):
            problems.append(
                at(
                    start_path,
                    "G010",
                    f"the start point ({start[0]:g}, {start[1]:g}) is inside a hole",
                    "holes are obstacles; start the robot in the free workspace",
                )
            )
    return problems
