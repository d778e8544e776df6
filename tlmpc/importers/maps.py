"""Occupancy-grid maps and nav2 keepout / speed masks → a polygonal workspace and regions.

* Free space is the cells of value 0 (unknown space is *not* free), as the exact union of their
  squares (:mod:`tlmpc.importers.polygonize`).
* ``radius`` erodes free space by the robot's radius (configuration space of a disc robot),
  plus the margin the simplification may take back (see :func:`erosion`).
* The workspace's main piece is the free piece containing ``start`` (else the largest); its
  outer ring is the boundary, its inner rings the holes.  Every other free piece of at least
  ``min_area`` becomes a further workspace component; holes and pieces smaller than
  ``min_area`` are specks (holes filled, pieces dropped), except that with
  ``keep_obstacles`` (a robot with a body) every hole is kept, however small.
* Rings are simplified within ``tolerance`` (default: one cell), never moving the boundary by
  more than that.
* A keepout mask's occupied cells (value 100) and a speed mask's limited cells (values 1..100)
  become regions ``keepout_1``, ``keepout_2``, ... and ``speed_<value>_<k>``, with groups
  ``keepout`` and ``speed_<value>`` naming all the pieces.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import shapely
from shapely.geometry import LineString, MultiPolygon, Polygon
from shapely.geometry import Point as ShapelyPoint
from shapely.geometry.base import BaseGeometry
from shapely.ops import split

from tlmpc.base.errors import UsageError, error
from tlmpc.importers.occupancy import FREE, OCCUPIED, OccupancyGrid, read_map
from tlmpc.importers.polygonize import (
    ARC_CLEARANCE,
    cells_to_geometry,
    drop_small_holes,
    erode,
    polygons,
    to_world,
)
from tlmpc.io.schema_check import MISSION_COORDINATE_LIMIT

Point = tuple[float, float]
Ring = tuple[Point, ...]

#: Default speck threshold, in cells: obstacle specks and region pieces smaller are dropped.
DEFAULT_MIN_CELLS = 4.0

#: Free pieces a map may have (each becomes a workspace component the planner meshes).
MAX_PIECES = 2_000


@dataclass(frozen=True, slots=True, kw_only=True)
class ImportSettings:
    """How a map becomes polygons (every length in map units, metres for ROS maps)."""

    radius: float = 0.0
    tolerance: float | None = None  # default: one cell
    min_area: float | None = None  # default: DEFAULT_MIN_CELLS cells
    start: Point | None = None
    #: Keep every obstacle however small (``min_area`` then drops only free specks): a robot
    #: with a body can hit an obstacle of a few cells, so none may vanish from its map.
    keep_obstacles: bool = False


@dataclass(frozen=True, slots=True, kw_only=True)
class ImportedMap:
    """A workspace and regions read from a map and its masks."""

    boundary: Ring
    holes: tuple[Ring, ...]
    #: further free pieces (not connected to the main one), each an outer ring and its holes
    components: tuple[tuple[Ring, tuple[Ring, ...]], ...]
    regions: Mapping[str, Ring]
    groups: Mapping[str, tuple[str, ...]]
    free_cells_area: float
    workspace_area: float
    resolution: float
    tolerance: float
    source: str
    #: how far free space was eroded (:func:`erosion` of the radius and the tolerance)
    erosion: float = 0.0
    #: obstacle specks filled: holes smaller than ``min_area`` by their exact cell area
    speckles_dropped: int = 0
    #: every file read: the map YAML, its image, and those of the masks
    inputs: tuple[str, ...] = ()


def _ring(polygon_ring: Any) -> Ring:
    coords = list(polygon_ring.coords)[:-1]
    return tuple((float(x), float(y)) for x, y in coords)


def _fail(code: str, message: str, file: str, hint: str | None = None) -> UsageError:
    return UsageError(error(code, message, hint=hint, file=file))


def free_geometry(grid: OccupancyGrid) -> BaseGeometry:
    """World-coordinate free space (cells of value 0) of a grid."""
    return to_world(cells_to_geometry(grid.values == FREE), grid.resolution, grid.origin)


def _to_grid(grid: OccupancyGrid, point: Point) -> Point:
    """World coordinates to grid coordinates (cells, y up): the inverse of ``to_world``."""
    ox, oy, yaw = grid.origin
    dx, dy = point[0] - ox, point[1] - oy
    c, s = math.cos(yaw), math.sin(yaw)
    return (c * dx + s * dy) / grid.resolution, (-s * dx + c * dy) / grid.resolution


def erosion(radius: float, tolerance: float) -> float:
    """How far free space is eroded for a disc robot of ``radius`` whose workspace is then
    simplified within ``tolerance``: ``radius + tolerance / ARC_CLEARANCE`` (0 without a radius).

    The erosion keeps ``ARC_CLEARANCE`` of its depth from every non-free cell (its arcs are
    chords), and the simplification moves the boundary by at most ``tolerance``, toward the
    obstacles too; eroding by the radius alone would leave the robot up to ``tolerance`` closer
    to them than its radius.  With the margin every point of the written workspace is at least
    ``radius * ARC_CLEARANCE`` from every non-free cell.
    """
    return radius + tolerance / ARC_CLEARANCE if radius > 0 else 0.0


def _free_pieces(
    grid: OccupancyGrid, depth: float, start: Point | None, min_cells: float
) -> tuple[Polygon, list[Polygon]]:
    """The free pieces eroded by ``depth`` (map units), in grid units: the one containing
    ``start`` (else the largest), and every other piece of at least ``min_cells`` cells
    (smaller ones are specks)."""
    free = erode(cells_to_geometry(grid.values == FREE), depth / grid.resolution)
    pieces = polygons(free)
    if not pieces:
        raise _fail(
            "M010",
            "the map has no free space"
            + (
                f" left after eroding by {depth:g} (the radius plus the simplification tolerance)"
                if depth
                else ""
            ),
            grid.source,
            hint="free cells are those with occupancy below free_thresh; "
            "check negate, the thresholds, the radius and the tolerance",
        )
    chosen: Polygon | None = None
    if start is not None:
        point = ShapelyPoint(_to_grid(grid, start))
        chosen = next((p for p in pieces if p.covers(point)), None)
    if chosen is None:
        chosen = max(pieces, key=lambda p: p.area)
    others = [p for p in pieces if p is not chosen and p.area >= min_cells]
    if len(others) >= MAX_PIECES:
        raise _fail(
            "M019",
            f"the map has {len(others) + 1:,} separate free pieces of at least the minimum "
            f"area, more than {MAX_PIECES:,} (a noise or dither pattern?)",
            grid.source,
            hint="clean the map, or raise the minimum area (--min-area, workspace.min_area) "
            "so that specks are dropped",
        )
    others.sort(key=lambda p: (-p.area, p.bounds))
    return chosen, others


def _labels(grid: OccupancyGrid, masks: list[npt.NDArray[np.int16]]) -> npt.NDArray[np.int64]:
    """One label per distinct combination of mask values (0 where no mask applies)."""
    if not masks:
        return np.zeros(grid.shape, dtype=np.int64)
    stacked = np.stack([m.astype(np.int64) + 1 for m in masks], axis=-1)  # -1..100 -> 0..101
    codes = np.zeros(grid.shape, dtype=np.int64)
    for layer in range(stacked.shape[-1]):
        codes = codes * 102 + stacked[..., layer]
    _, inverse = np.unique(codes, return_inverse=True)
    return inverse.reshape(grid.shape).astype(np.int64)


def _faces(linework: BaseGeometry) -> list[Polygon]:
    parts = getattr(linework, "geoms", None)
    lines = list(parts) if parts is not None else [linework]
    return polygons(shapely.polygonize(lines))


def _simplified(noded: BaseGeometry, tolerance: float, rounds: int = 8) -> BaseGeometry:
    """The chains of ``noded`` simplified within ``tolerance``, with the exact course put
    back wherever the simplification pinched the free space.

    Douglas-Peucker with topology preserved keeps chains from crossing, not from nearly
    touching: a wall a cell away from a pillar (or from its own other side, across an inlet)
    can end up a ten-thousandth of a cell away, a passage narrower than anything in the map
    (G021) and needles in the mesh.  A kept vertex closer than half the tolerance to a
    simplified segment it is not next to marks a pinch; that segment and the two at the
    vertex get back every exact vertex between their ends (a kept vertex is an exact one), and
    the check runs again.  Elsewhere the simplification stands.
    """
    simple = noded.simplify(tolerance, preserve_topology=True)
    exact_parts = [np.asarray(g.coords) for g in getattr(noded, "geoms", [noded])]
    simple_parts = [np.asarray(g.coords) for g in getattr(simple, "geoms", [simple])]
    if len(exact_parts) != len(simple_parts):
        return simple
    kept: list[list[int]] = []
    for exact, part in zip(exact_parts, simple_parts, strict=True):
        where: dict[tuple[float, float], int] = {}
        for index, (x, y) in enumerate(exact.tolist()):
            where.setdefault((x, y), index)
        indices = [where.get((x, y), -1) for x, y in part.tolist()]
        if indices and len(part) > 1 and part[0].tolist() == part[-1].tolist():
            indices[-1] = len(exact) - 1  # a closed chain ends where it starts
        if -1 in indices or indices != sorted(indices):
            return simple  # not a subset of the exact vertices in order: leave it be
        kept.append(indices)
    limit = 0.75 * tolerance
    for _ in range(rounds):
        segments = [
            (chain, k) for chain, indices in enumerate(kept) for k in range(len(indices) - 1)
        ]
        if not segments:
            break
        starts = np.array([exact_parts[c][kept[c][k]] for c, k in segments])
        ends = np.array([exact_parts[c][kept[c][k + 1]] for c, k in segments])
        lines = shapely.linestrings(np.stack([starts, ends], axis=1))
        tree = shapely.STRtree(lines)
        vertices = [(c, k) for c, indices in enumerate(kept) for k in range(len(indices))]
        points = shapely.points(np.array([exact_parts[c][kept[c][k]] for c, k in vertices]))
        near_point, near_line = tree.query(points, predicate="dwithin", distance=limit)
        widen: set[tuple[int, int]] = set()
        for v, sgm in zip(near_point.tolist(), near_line.tolist(), strict=True):
            chain, k = vertices[v]
            other, j = segments[sgm]
            if other == chain and k in (j, j + 1):
                continue  # the vertex's own segment
            point = exact_parts[chain][kept[chain][k]]
            if any((exact_parts[other][kept[other][e]] == point).all() for e in (j, j + 1)):
                continue  # a junction: the chains meet there
            if exact_parts[other][kept[other][j] : kept[other][j + 1] + 1].shape[0] <= 2:
                continue  # an exact segment already: the gap is the map's own
            widen.add((other, j))
            for e in (k - 1, k):
                if 0 <= e < len(kept[chain]) - 1:
                    widen.add((chain, e))
        if not widen:
            break
        for chain in {c for c, _ in widen}:
            indices = kept[chain]
            grown: list[int] = []
            for e in range(len(indices) - 1):
                grown.append(indices[e])
                if (chain, e) in widen:
                    grown.extend(range(indices[e] + 1, indices[e + 1]))
            grown.append(indices[-1])
            kept[chain] = grown
    return shapely.MultiLineString(
        [exact[indices] for exact, indices in zip(exact_parts, kept, strict=True)]
    )


def _coverage(
    workspace: BaseGeometry, labels: npt.NDArray[np.int64], tolerance: float
) -> tuple[list[Polygon], dict[int, list[BaseGeometry]]]:
    """The workspace cut by the label cells, simplified as one coverage (shared edges shared).

    Simplifying the workspace and each mask piece on its own would leave region edges running
    beside walls a fraction of a cell away, or crossing them at tiny angles: slivers that
    explode a quality mesh.  Instead the workspace's rings and the label boundaries inside it
    are noded into one linework, merged into chains between junctions, and the chains are
    simplified together by Douglas-Peucker with topology preserved (junctions stay, no chain
    crosses another): every edge moves once for all the faces that share it, by at most
    ``tolerance``.  The faces are then polygonized and matched to the exact faces by overlap.
    ``workspace`` may have several pieces (a multipolygon); every piece is returned.
    """
    present = [int(v) for v in np.unique(labels)]
    lines: list[BaseGeometry] = [workspace.boundary]
    if len(present) > 1:
        # Label edges are clipped to a cell beyond the workspace, not to the workspace itself:
        # a clipped end computed in floating point would stop a hair short of the wall and be
        # dropped by polygonize as a dangle; crossing the wall, the noding splits it exactly.
        reach = workspace.buffer(1.0, quad_segs=2)
        for label in present:
            edges = cells_to_geometry(labels == label).boundary
            lines.append(shapely.intersection(edges, reach))
    noded = shapely.line_merge(shapely.union_all(lines))
    exact: list[Polygon] = []
    exact_labels: list[int | None] = []
    rows, cols = labels.shape
    for face in _faces(noded):
        inside = face.representative_point()
        exact.append(face)
        if workspace.covers(inside):
            row = min(max(math.floor(inside.y), 0), rows - 1)
            col = min(max(math.floor(inside.x), 0), cols - 1)
            exact_labels.append(int(labels[row, col]))
        else:
            exact_labels.append(None)  # the inside of a hole
    faces, face_labels = exact, exact_labels
    if tolerance > 0:
        simple = _faces(_simplified(noded, tolerance))
        tree = shapely.STRtree(exact)
        matched: list[int | None] = []
        for face in simple:
            candidates = tree.query(face)
            overlaps = [face.intersection(exact[int(k)]).area for k in candidates]
            best = int(candidates[int(np.argmax(overlaps))]) if len(candidates) else -1
            matched.append(exact_labels[best] if best >= 0 and max(overlaps) > 0 else None)
        kept_area = sum(f.area for f, lab in zip(simple, matched, strict=True) if lab is not None)
        # Each edge moved by at most the tolerance, so the area cannot change by more than
        # tolerance x total edge length; more means the simplified linework lost a junction.
        area_kept = abs(kept_area - workspace.area) <= tolerance * workspace.length + 1e-9
        holes = [f for f, lab in zip(simple, matched, strict=True) if lab is None]
        if area_kept and _obstacles_kept(workspace, holes):
            faces, face_labels = simple, matched
    kept = [f for f, lab in zip(faces, face_labels, strict=True) if lab is not None]
    merged = polygons(shapely.union_all(kept))
    by_label: dict[int, list[BaseGeometry]] = {}
    for face, face_label in zip(faces, face_labels, strict=True):
        if face_label is not None:
            by_label.setdefault(face_label, []).append(face)
    return merged, by_label


def _obstacles_kept(workspace: BaseGeometry, simple_holes: list[Polygon]) -> bool:
    """Whether every hole of ``workspace`` (an obstacle) overlaps one of ``simple_holes``, the
    simplified faces matched to no free face.

    Simplified faces take the label of the exact face they overlap most, so a hole simplified
    into a sliver lying mostly over free cells would be labelled free and the obstacle would
    vanish from the map: then the import keeps the exact faces instead.
    """
    exact_holes = [Polygon(ring) for piece in polygons(workspace) for ring in piece.interiors]
    if not exact_holes:
        return True
    tree = shapely.STRtree(simple_holes)
    return all(
        any(hole.intersection(simple_holes[int(k)]).area > 0 for k in tree.query(hole))
        for hole in exact_holes
    )


def _simple_parts(piece: Polygon, free: BaseGeometry, members: BaseGeometry) -> list[Polygon]:
    """Simple polygons (regions have no holes) covering ``piece`` and its fillable holes.

    A hole of a mask piece is usually an obstacle, which the region may cover: only its outer
    ring is kept.  But a hole may enclose free space of another workspace piece (a free pocket
    inside a rack) that the mask does not mark; filling that hole would label the pocket
    wrongly.  Such a piece is cut by a vertical line through the hole, opening it, until every
    hole left is fillable.
    """

    def fillable(ring: Any) -> bool:
        inside = Polygon(ring).intersection(free)
        return bool(inside.difference(members).area <= 1e-9 * max(inside.area, 1.0))

    blocking = [ring for ring in piece.interiors if not fillable(ring)]
    if not blocking:
        return [Polygon(piece.exterior)]
    x = Polygon(blocking[0]).representative_point().x  # strictly inside the hole
    _, miny, _, maxy = piece.bounds
    cut = LineString([(x, miny - 1.0), (x, maxy + 1.0)])
    return [
        simple
        for part in polygons(split(piece, cut))
        for simple in _simple_parts(part, free, members)
    ]


def _exact_free(
    grid: OccupancyGrid, settings: ImportSettings, depth: float, min_area_cells: float
) -> tuple[Polygon, list[Polygon], int]:
    """The free pieces eroded by ``depth``, in grid units before simplification, with their
    specks decided: the main piece, the other pieces of at least ``min_area_cells``, and how
    many holes smaller than that were filled.

    Specks are judged here, on the exact cell areas, and only here: simplification within
    one cell can take a 4-cell L, S or T obstacle to a triangle of 3 cells or less, which
    would then count as a speck and turn real occupied cells into free space.
    """
    main, others = _free_pieces(grid, depth, settings.start, min_area_cells)
    holes = 0.0 if settings.keep_obstacles else min_area_cells
    pieces = [main, *others]
    filled = [drop_small_holes(p, holes) for p in pieces]
    dropped = sum(len(a.interiors) - len(b.interiors) for a, b in zip(pieces, filled, strict=True))
    return filled[0], filled[1:], dropped


def _check_settings(settings: ImportSettings, file: str) -> None:
    """Refuse (M012) a radius, tolerance or minimum area that is negative or not a finite
    number: NaN compares false with everything, so a NaN minimum area would silently drop
    every obstacle, and an infinite radius erodes nothing well-defined."""
    for what, value in (
        ("radius", settings.radius),
        ("tolerance", settings.tolerance),
        ("minimum area", settings.min_area),
    ):
        if value is not None and not (math.isfinite(value) and value >= 0):
            raise _fail(
                "M012",
                f"the {what} must be a finite number >= 0, got {value:g}",
                file,
                hint="--radius, --tolerance and --min-area are lengths and areas in map units",
            )
    if settings.start is not None and not all(math.isfinite(v) for v in settings.start):
        raise _fail("M018", f"the start must be finite, got {settings.start}", file)


def _check_reach(grid: OccupancyGrid, shapes: list[Polygon]) -> None:
    """Refuse (M007) a map whose imported coordinates lie beyond the mission format's limit:
    the mission written from it, or loaded with it, would be one ``tlmpc check`` rejects."""
    coordinates = shapely.get_coordinates(shapes)
    if not coordinates.size or np.abs(coordinates).max() <= MISSION_COORDINATE_LIMIT:
        return
    row, axis = np.unravel_index(int(np.argmax(np.abs(coordinates))), coordinates.shape)
    value = float(coordinates[row, axis])
    ox, oy, _ = grid.origin
    # the origin alone out of range is the origin's fault; else the cells carry it there
    key = "origin" if max(abs(ox), abs(oy)) > MISSION_COORDINATE_LIMIT else "resolution"
    rows, cols = grid.shape
    place = grid.places.get(key)
    raise UsageError(
        error(
            "M007",
            f"the imported map reaches {'xy'[int(axis)]} = {value:g}, beyond the "
            f"±{MISSION_COORDINATE_LIMIT:g} a mission's coordinates may have",
            hint=f"the map is {cols}x{rows} cells of {grid.resolution:g} m "
            f"({cols * grid.resolution:g} m x {rows * grid.resolution:g} m) from the origin "
            f"({ox:g}, {oy:g}): check `origin` and `resolution` (metres per cell)",
            file=grid.source,
            line=place[0] if place else None,
            col=place[1] if place else None,
        )
    )


def _in_cells(area: float, cell_area: float) -> float:
    """``area`` in cells, a whole number of cells when it is one up to rounding: 0.0054 m² at
    0.03 m is 6 cells, not 6.000000000000001 (which would drop 6-cell obstacles)."""
    cells = area / cell_area
    whole = round(cells)
    return float(whole) if abs(cells - whole) <= 1e-9 * max(1.0, cells) else cells


def import_map(
    map_path: Path,
    settings: ImportSettings = ImportSettings(),
    *,
    keepout: Path | None = None,
    speed: Path | None = None,
) -> ImportedMap:
    """Read a map (and masks) and build the workspace and regions."""
    _check_settings(settings, str(map_path))
    grid = read_map(map_path)
    tolerance = grid.resolution if settings.tolerance is None else settings.tolerance
    min_area = (
        DEFAULT_MIN_CELLS * grid.cell_area() if settings.min_area is None else settings.min_area
    )
    cell_area = grid.cell_area()
    min_cells = _in_cells(min_area, cell_area)
    depth = erosion(settings.radius, tolerance)
    exact_main, exact_others, dropped = _exact_free(grid, settings, depth, min_cells)
    mask_grids: list[tuple[str, Path, OccupancyGrid]] = []
    for prefix, path in (("keepout", keepout), ("speed", speed)):
        if path is None:
            continue
        mask = read_map(path)
        if (
            mask.shape != grid.shape
            or mask.resolution != grid.resolution
            or mask.origin != grid.origin
        ):
            # at the mask's first key that differs from the map's (its image for the size)
            key = (
                "image"
                if mask.shape != grid.shape
                else "resolution"
                if mask.resolution != grid.resolution
                else "origin"
            )
            line, col = mask.places.get(key, (None, None))
            raise UsageError(
                error(
                    "M013",
                    f"the mask is {mask.shape[1]}x{mask.shape[0]} cells at {mask.resolution:g} "
                    f"from origin {list(mask.origin)}, the map {grid.shape[1]}x{grid.shape[0]} "
                    f"at {grid.resolution:g} from {list(grid.origin)}",
                    hint="a mask must have the map's size, resolution and origin",
                    file=str(path),
                    line=line,
                    col=col,
                )
            )
        mask_grids.append((prefix, path, mask))
    layers = [m.values for _, _, m in mask_grids]
    labels = _labels(grid, layers)
    exact = MultiPolygon([exact_main, *exact_others]) if exact_others else exact_main
    simplified, pieces = _coverage(exact, labels, tolerance / grid.resolution)
    if not simplified:
        raise _fail(
            "M011",
            "the free space vanishes when simplified",
            grid.source,
            hint="lower the simplification tolerance (import-map --tolerance, or the map's"
            " `tolerance` in a mission; 0 keeps the cells' own outline)",
        )
    # Each exact piece, its specks already decided on exact areas, is the simplified piece
    # overlapping it most; their holes are the exact holes kept, however small simplified.
    tree = shapely.STRtree(simplified)

    def counterpart(piece: Polygon) -> Polygon:
        near = [simplified[int(k)] for k in tree.query(piece)] or simplified
        return max(near, key=lambda p: (p.intersection(piece).area, p.area))

    main = counterpart(exact_main)
    others = list({id(p): p for p in map(counterpart, exact_others) if p is not main}.values())
    others.sort(key=lambda p: (-p.area, p.bounds))
    kept_cells = [main, *others]
    outer_cells = shapely.union_all([Polygon(p.exterior) for p in kept_cells])
    shapely.prepare(outer_cells)
    free_union = shapely.union_all(kept_cells)
    regions: dict[str, Ring] = {}
    groups: dict[str, tuple[str, ...]] = {}
    for prefix, _, mask in mask_grids:
        if prefix == "keepout":
            wanted = [OCCUPIED]
        else:
            wanted = sorted({int(v) for v in np.unique(mask.values) if 0 < v <= OCCUPIED})
        for value in wanted:
            group = prefix if prefix == "keepout" else f"{prefix}_{value}"
            members = [
                piece
                for label, faces in pieces.items()
                if np.any(mask.values[labels == label] == value)
                for piece in faces
            ]
            if not members:
                continue
            covered = shapely.union_all(members)
            merged = polygons(covered)
            outers = [
                simple
                for p in merged
                if p.area >= min_cells
                and outer_cells.covers(p)
                and p.intersection(free_union).area > 0
                for simple in _simple_parts(p, free_union, covered)
            ]
            outers = [to_world(p, grid.resolution, grid.origin) for p in outers]
            outers.sort(key=lambda p: (-p.area, p.bounds))
            if outers:
                names = {f"{group}_{k}": _ring(p.exterior) for k, p in enumerate(outers, 1)}
                regions.update(names)
                groups[group] = tuple(names)
    world = [to_world(p, grid.resolution, grid.origin) for p in kept_cells]
    assert all(isinstance(p, Polygon) for p in world)
    _check_reach(grid, [*world, *(Polygon(ring) for ring in regions.values())])
    workspace = world[0]
    free_cells = float(np.count_nonzero(grid.values == FREE)) * grid.cell_area()
    return ImportedMap(
        boundary=_ring(workspace.exterior),
        holes=tuple(_ring(r) for r in workspace.interiors),
        components=tuple(
            (_ring(p.exterior), tuple(_ring(r) for r in p.interiors)) for p in world[1:]
        ),
        regions=regions,
        groups=groups,
        free_cells_area=free_cells,
        workspace_area=float(sum(p.area for p in world)),
        resolution=grid.resolution,
        tolerance=tolerance,
        source=str(map_path),
        erosion=depth,
        speckles_dropped=dropped,
        inputs=tuple(
            name for g in (grid, *(m for _, _, m in mask_grids)) for name in (g.source, g.image)
        ),
    )
