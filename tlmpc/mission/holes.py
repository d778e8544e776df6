"""Holes as the triangulator needs them, and narrow passages found before meshing.

Overlapping holes are one obstacle to the robot; the triangulator needs them as one polygon,
so they are merged (their union) with a note (G020) saying which holes, as numbered in the file
(1 for the first), became one.  Holes that only touch are kept as given: they triangulate as
they are.  Free space enclosed by merged holes cannot
be reached from outside them: the merged hole is the union's outer ring and the note says so.

A passage of the free space far narrower than the map (by default under 1/1000 of the
workspace's size) forces the mesher into thousands of needle triangles and the robot through a
gap it cannot really use; it is reported (G021, a warning) at the narrowest place, before any
meshing.  Both run in ``tlmpc check`` and at the start of ``tlmpc compile``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tlmpc.base.errors import Diagnostic
from tlmpc.mission.model import Mission, Point, Polygon
from tlmpc.mission.shapes import AREA_TOLERANCE

#: A passage narrower than this fraction of the workspace's size is reported (G021).
NARROW_FRACTION = 1e-3


@dataclass(frozen=True, slots=True, kw_only=True)
class MergedHoles:
    """The holes after merging, and which original holes (0-based) each one came from."""

    holes: tuple[Polygon, ...]
    sources: tuple[tuple[int, ...], ...]
    enclosed: tuple[bool, ...]  # the union enclosed free space, now part of the hole


def _ring(coords: Sequence[tuple[float, ...]]) -> Polygon:
    points = [(float(x), float(y)) for x, y, *_ in coords]
    if len(points) > 1 and points[0] == points[-1]:
        points.pop()
    return tuple(points)


def _overlap_groups(shapes: Sequence[Any]) -> list[list[int]]:
    """The holes (shapely polygons) grouped by overlapping interiors (transitively), each
    group in file order and the groups by their first hole."""
    from shapely import STRtree

    parent = list(range(len(shapes)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    tree = STRtree(shapes)
    for i, shape in enumerate(shapes):
        for j in tree.query(shape).tolist():
            if j <= i:
                continue
            # an overlap; holes that only touch (a shared edge or corner) already triangulate
            # as they are, and keeping them keeps their meshes and plans unchanged
            overlap = shape.intersection(shapes[j]).area
            if overlap > AREA_TOLERANCE * max(shape.area, shapes[j].area):
                parent[find(j)] = find(i)
    groups: dict[int, list[int]] = {}
    for i in range(len(shapes)):
        groups.setdefault(find(i), []).append(i)
    return sorted(groups.values())


def _group_union(group: Sequence[Any]) -> Any:
    """The union of one group of overlapping holes (one polygon: the group is connected)."""
    from shapely import union_all

    union = union_all(group)
    if union.geom_type != "Polygon":  # pragma: no cover - groups are connected by area
        union = max(union.geoms, key=lambda g: g.area)
    return union


def merge_holes(holes: Sequence[Polygon]) -> MergedHoles:
    """Merge holes whose interiors overlap (transitively); keep the others exactly as given.
    A merged hole is its union's outer ring: the free space it encloses is unreachable."""
    from shapely import Polygon as ShapelyPolygon

    shapes = [ShapelyPolygon(h) for h in holes]
    merged: list[Polygon] = []
    sources: list[tuple[int, ...]] = []
    enclosed: list[bool] = []
    for members in _overlap_groups(shapes):
        if len(members) == 1:
            merged.append(tuple(holes[members[0]]))
            sources.append((members[0],))
            enclosed.append(False)
            continue
        union = _group_union([shapes[i] for i in members])
        merged.append(_ring(list(union.exterior.coords)))
        sources.append(tuple(members))
        enclosed.append(len(union.interiors) > 0)
    return MergedHoles(holes=tuple(merged), sources=tuple(sources), enclosed=tuple(enclosed))


def obstacle(holes: Sequence[Any]) -> Any:
    """What the holes (shapely polygons) take from the free space once merged: their union,
    with the free space that overlapping holes enclose filled (as :func:`merge_holes` makes
    it); None without holes.  The checks of regions and the start use it, so that a region or
    start in an enclosed pocket is refused by ``tlmpc check`` as by the compile."""
    from shapely import Polygon as ShapelyPolygon
    from shapely import union_all

    if not holes:
        return None
    pieces = []
    for members in _overlap_groups(holes):
        group = [holes[i] for i in members]
        pieces.append(group[0] if len(group) == 1 else ShapelyPolygon(_group_union(group).exterior))
    return union_all(pieces)


def merge_notes(
    merged: MergedHoles, file: str | None, lines: Sequence[int] | None
) -> list[Diagnostic]:
    """One G020 note per merged group, at the first hole of the group."""
    notes: list[Diagnostic] = []
    for members, closed in zip(merged.sources, merged.enclosed, strict=True):
        if len(members) < 2:
            continue
        numbers = [str(i + 1) for i in members]
        listing = ", ".join(numbers[:-1]) + " and " + numbers[-1]
        message = f"holes {listing} overlap: merged into one obstacle"
        if closed:
            message += " (the free space they enclose is unreachable and is now part of it)"
        notes.append(
            Diagnostic(
                code="G020",
                severity="note",
                message=message,
                hint="holes are numbered from 1 in the order of `workspace.holes`",
                file=file,
                line=lines[members[0]] if lines is not None else None,
                col=None,
            )
        )
    return notes


#: Rings with more vertices than this are simplified (by far less than a passage's width)
#: before the search: a finely sampled curve would otherwise pair every edge with hundreds of
#: its neighbours.
_SIMPLIFY_ABOVE = 1000
#: At most this many pairs of close edges are examined; beyond, the search stops (G040 note).
MAX_PAIRS = 2_000_000
_CHUNK = 50_000


def narrow_passages(
    boundary: Polygon, holes: Sequence[Polygon], *, fraction: float = NARROW_FRACTION
) -> list[tuple[float, Point, Point, int]]:
    """Passages of the free space narrower than ``fraction`` × the workspace size.

    Each is ``(width, a, b, ring)``: see :func:`passages_narrower_than`; ``ring`` is the
    higher of the two rings' numbers.
    """
    from shapely import Polygon as ShapelyPolygon

    minx, miny, maxx, maxy = ShapelyPolygon(boundary).bounds
    limit = fraction * max(maxx - minx, maxy - miny)
    return sorted(
        (width, a, b, rings[1])
        for width, a, b, rings in passage_search(boundary, holes, width=limit)[0]
    )


def passages_narrower_than(
    boundary: Polygon, holes: Sequence[Polygon], *, width: float
) -> list[tuple[float, Point, Point, tuple[int, int]]]:
    """Passages of the free space narrower than ``width``.

    Each is ``(width, a, b, (lower, higher))``: the two closest points across the passage
    and the numbers of the two rings that bound it (0 the boundary, k the k-th hole), one
    per pair of rings.  Edges of the
    boundary and holes are compared pairwise (through a spatial index); a pair counts when the
    segment joining their closest points crosses free space, so a thin obstacle or a sharp
    corner is no passage.  Edges that touch (neighbours sharing a vertex) are at distance 0 and
    skipped; so are two edges of one ring joined along it by less than twice their distance
    (the chord of a finely sampled curve, not a passage).
    """
    return passage_search(boundary, holes, width=width)[0]


def passage_search(
    boundary: Polygon,
    holes: Sequence[Polygon],
    *,
    width: float | None = None,
    max_pairs: int = MAX_PAIRS,
) -> tuple[list[tuple[float, Point, Point, tuple[int, int]]], bool]:
    """:func:`passages_narrower_than` (``width`` defaults to :data:`NARROW_FRACTION` × the
    workspace size), and whether the search examined every close pair of edges."""
    import numpy as np
    import shapely

    arrays = [np.asarray(ring, dtype=float).reshape(-1, 2) for ring in [boundary, *holes]]
    hole_rings = [shapely.linearrings(h) for h in arrays[1:]]
    free = shapely.polygons(shapely.linearrings(arrays[0]), holes=hole_rings or None)
    minx, miny, maxx, maxy = shapely.bounds(free).tolist()
    limit = NARROW_FRACTION * max(maxx - minx, maxy - miny) if width is None else width
    starts: list[np.ndarray] = []
    ring_of: list[np.ndarray] = []
    for number, points in enumerate(arrays):
        if len(points) > _SIMPLIFY_ABOVE:
            # Douglas-Peucker on the ring alone (the topology-preserving variant is 15 times
            # slower); moving edges by 1/1000 of the passage limit cannot hide a passage.
            simple = shapely.simplify(shapely.linearrings(points), limit * 1e-3)
            if shapely.get_num_coordinates(simple) >= 4:
                points = shapely.get_coordinates(simple)[:-1]
        starts.append(points)
        ring_of.append(np.full(len(points), number))
    begin = np.concatenate(starts)
    finish = np.concatenate([np.roll(points, -1, axis=0) for points in starts])
    rings = np.concatenate(ring_of)
    # Position along its ring of each edge's start, and each ring's perimeter.
    length = np.hypot(*(finish - begin).T)
    along = np.zeros(len(begin))
    perimeter = np.zeros(len(starts))
    first = 0
    for number, points in enumerate(starts):
        last = first + len(points)
        along[first:last] = np.concatenate(([0.0], np.cumsum(length[first : last - 1])))
        perimeter[number] = length[first:last].sum()
        first = last
    lines = shapely.linestrings(np.stack([begin, finish], axis=1))
    tree = shapely.STRtree(lines)
    shapely.prepare(free)
    found: list[tuple[float, Point, Point, tuple[int, int]]] = []
    pair_of: list[tuple[int, int]] = []
    examined = 0
    complete = True
    for chunk in range(0, len(lines), _CHUNK):
        pairs = tree.query(lines[chunk : chunk + _CHUNK], predicate="dwithin", distance=limit)
        i, j = pairs[0] + chunk, pairs[1]
        keep = j > i
        i, j = i[keep], j[keep]
        examined += len(i)
        if examined > max_pairs:
            complete = False
            break
        gaps = shapely.shortest_line(lines[i], lines[j])
        gap_width = shapely.length(gaps)
        ok = (gap_width > 0.0) & (gap_width < limit)  # 0: neighbouring edges, or touching
        same = rings[i] == rings[j]
        # Ring length between the two edges, the shorter way round (edges themselves left out).
        inner = along[j] - along[i] - length[i]
        outer = perimeter[rings[i]] - (along[j] + length[j] - along[i])
        ok &= ~same | (np.minimum(inner, outer) >= 2.0 * gap_width)
        i, j, gaps, gap_width = i[ok], j[ok], gaps[ok], gap_width[ok]
        middle = shapely.line_interpolate_point(gaps, 0.5, normalized=True)
        inside = shapely.contains(free, middle)
        ends = shapely.get_coordinates(gaps[inside]).reshape(-1, 2, 2)
        for k, (a, b) in zip(np.flatnonzero(inside).tolist(), ends.tolist(), strict=True):
            low, high = sorted((int(rings[i[k]]), int(rings[j[k]])))
            found.append((float(gap_width[k]), (a[0], a[1]), (b[0], b[1]), (low, high)))
            pair_of.append((low, high))
    # one report per pair of rings (a hole and its neighbour): the narrowest place between them
    narrowest: dict[tuple[int, int], int] = {}
    for index, passage in enumerate(found):
        key = pair_of[index]
        if key not in narrowest or passage[0] < found[narrowest[key]][0]:
            narrowest[key] = index
    return sorted(found[i] for i in narrowest.values()), complete


def workspace_notes(mission: Mission, text: str | None = None) -> tuple[Mission, list[Diagnostic]]:
    """The mission with its holes merged, and the G020 notes and G021 warnings.

    ``text`` is the mission file's YAML (read from ``mission.source`` when not given); it only
    serves to put each diagnostic on the line of the hole or boundary it is about.
    """
    from tlmpc.mission.plain_geometry import axis_rectangle
    from tlmpc.mission.yamlpos import load_positioned

    file = mission.source
    holes = mission.workspace.holes
    rect = axis_rectangle(mission.workspace.boundary)
    if not holes and rect is not None:
        width, height = rect[2] - rect[0], rect[3] - rect[1]
        if min(width, height) > 2 * NARROW_FRACTION * max(width, height):
            # nothing to merge, and the only passages of a rectangle are its width and height
            return mission, []
    merged = merge_holes(holes)
    boundary = mission.workspace.boundary
    passages, complete = passage_search(boundary, merged.holes)
    hole_lines: list[int] | None = None
    boundary_line: int | None = None
    noted = len(merged.holes) != len(holes) or passages or not complete
    if file is not None and noted:  # the file is read again only to place a diagnostic
        try:
            source_text = text if text is not None else Path(file).read_text(encoding="utf-8")
        except OSError:
            source_text = None
        doc = load_positioned(source_text, file)[0] if source_text is not None else None
        if doc is not None:
            hole_lines = [doc.value_at(("workspace", "holes", i))[0] for i in range(len(holes))]
            boundary_line = doc.value_at(("workspace", "boundary"))[0]
    diagnostics = merge_notes(merged, file, hole_lines)
    xs = [p[0] for p in boundary]
    ys = [p[1] for p in boundary]
    size = max(max(xs) - min(xs), max(ys) - min(ys))
    if not complete:
        diagnostics.append(
            Diagnostic(
                code="G040",
                severity="note",
                message=f"the search for narrow passages stopped after {MAX_PAIRS:,} pairs of "
                "close edges; narrower passages may exist",
                hint="the outline has very many short, close edges; simplify it",
                file=file,
                line=boundary_line,
            )
        )
    for width, a, b, (_, ring) in passages:
        x, y = (a[0] + b[0]) / 2, (a[1] + b[1]) / 2
        line = boundary_line
        if ring > 0 and hole_lines is not None:
            line = hole_lines[merged.sources[ring - 1][0]]
        diagnostics.append(
            Diagnostic(
                code="G021",
                severity="warning",
                message=f"a passage only {width:.3g} wide at ({x:.6g}, {y:.6g}), "
                f"{size / width:.3g} times narrower than the map",
                hint="widen it or close it: the mesher fills it with needle triangles and "
                "the robot cannot really pass",
                file=file,
                line=line,
            )
        )
    if len(merged.holes) != len(holes):
        workspace = dataclasses.replace(mission.workspace, holes=merged.holes)
        mission = dataclasses.replace(mission, workspace=workspace)
    return mission, diagnostics
