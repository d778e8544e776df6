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

from tlmpc.errors import Diagnostic
from tlmpc.mission.geometry import AREA_TOLERANCE
from tlmpc.mission.model import Mission, Point, Polygon

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


def merge_holes(holes: Sequence[Polygon]) -> MergedHoles:
    """Merge holes whose interiors overlap (transitively); keep the others exactly as given."""
    from shapely import Polygon as ShapelyPolygon
    from shapely import STRtree, union_all

    shapes = [ShapelyPolygon(h) for h in holes]
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
    clusters: dict[int, list[int]] = {}
    for i in range(len(shapes)):
        clusters.setdefault(find(i), []).append(i)
    merged: list[Polygon] = []
    sources: list[tuple[int, ...]] = []
    enclosed: list[bool] = []
    for members in sorted(clusters.values()):
        if len(members) == 1:
            merged.append(tuple(holes[members[0]]))
            sources.append((members[0],))
            enclosed.append(False)
            continue
        union = union_all([shapes[i] for i in members])
        if union.geom_type != "Polygon":  # pragma: no cover - clusters are connected by area
            union = max(union.geoms, key=lambda g: g.area)
        merged.append(_ring(list(union.exterior.coords)))
        sources.append(tuple(members))
        enclosed.append(len(union.interiors) > 0)
    return MergedHoles(holes=tuple(merged), sources=tuple(sources), enclosed=tuple(enclosed))


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


def narrow_passages(
    boundary: Polygon, holes: Sequence[Polygon], *, fraction: float = NARROW_FRACTION
) -> list[tuple[float, Point, Point, int]]:
    """Passages of the free space narrower than ``fraction`` × the workspace size.

    Each is ``(width, a, b, ring)``: the two closest points across the passage and the ring
    that bounds it with the higher number (0 the boundary, k the k-th hole), one per pair of
    rings.  Edges of the
    boundary and holes are compared pairwise (through a spatial index); a pair counts when the
    segment joining their closest points crosses free space, so a thin obstacle or a sharp
    corner is no passage.  Edges that touch (neighbours sharing a vertex) are at distance 0 and
    skipped.
    """
    from shapely import LineString, STRtree, prepared, shortest_line
    from shapely import Polygon as ShapelyPolygon

    free = ShapelyPolygon(boundary, list(holes))
    minx, miny, maxx, maxy = ShapelyPolygon(boundary).bounds
    limit = fraction * max(maxx - minx, maxy - miny)
    segments: list[tuple[Point, Point]] = []
    rings: list[int] = []
    for number, ring in enumerate([boundary, *holes]):
        for k, a in enumerate(ring):
            segments.append((a, ring[(k + 1) % len(ring)]))
            rings.append(number)
    lines = [LineString(s) for s in segments]
    tree = STRtree(lines)
    inside = prepared.prep(free)
    found: list[tuple[float, Point, Point, int]] = []
    pair_of: dict[int, tuple[int, int]] = {}
    pairs = tree.query(lines, predicate="dwithin", distance=limit)
    for i, j in zip(pairs[0].tolist(), pairs[1].tolist(), strict=True):
        if j <= i:
            continue
        gap = shortest_line(lines[i], lines[j])
        width = gap.length
        if width <= 0.0 or width >= limit:  # 0: neighbouring edges, or edges that touch
            continue
        middle = gap.interpolate(0.5, normalized=True)
        if not inside.contains(middle):
            continue
        (ax, ay), (bx, by) = gap.coords
        found.append((width, (ax, ay), (bx, by), max(rings[i], rings[j])))
        pair_of[len(found) - 1] = (min(rings[i], rings[j]), max(rings[i], rings[j]))
    # one report per pair of rings (a hole and its neighbour): the narrowest place between them
    narrowest: dict[tuple[int, int], int] = {}
    for index, passage in enumerate(found):
        key = pair_of[index]
        if key not in narrowest or passage[0] < found[narrowest[key]][0]:
            narrowest[key] = index
    return sorted(found[i] for i in narrowest.values())


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
    hole_lines: list[int] | None = None
    boundary_line: int | None = None
    if file is not None:
        try:
            source_text = text if text is not None else Path(file).read_text(encoding="utf-8")
        except OSError:
            source_text = None
        doc = load_positioned(source_text, file)[0] if source_text is not None else None
        if doc is not None:
            hole_lines = [doc.value_at(("workspace", "holes", i))[0] for i in range(len(holes))]
            boundary_line = doc.value_at(("workspace", "boundary"))[0]
    diagnostics = merge_notes(merged, file, hole_lines)
    boundary = mission.workspace.boundary
    xs = [p[0] for p in boundary]
    ys = [p[1] for p in boundary]
    size = max(max(xs) - min(xs), max(ys) - min(ys))
    for width, a, b, ring in narrow_passages(boundary, merged.holes):
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
