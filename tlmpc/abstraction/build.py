"""Stage 3: the transition system D (triangles, adjacency, labels, start, components)."""

from __future__ import annotations

import time
from itertools import chain
from typing import Any

import numpy as np
import shapely

from tlmpc.abstraction.layout import PlanningLayout
from tlmpc.abstraction.lines import Lines
from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.abstraction.resolution import refuse_subgrid_features
from tlmpc.abstraction.starts import cells_in
from tlmpc.abstraction.triangulate import triangulate
from tlmpc.base.errors import Diagnostic, InvalidInputError, error
from tlmpc.mission.model import Mission


def locate(abstraction: Abstraction, point: tuple[float, float]) -> int:
    """Index of the triangle containing ``point`` (-1 if none); ties go to the lowest index."""
    return locate_in(abstraction.vertices, abstraction.triangles, point)


def locate_in(vertices: FloatArray, triangles: IntArray, point: tuple[float, float]) -> int:
    """:func:`locate` on raw arrays."""
    corners = vertices[triangles]
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    p = np.asarray(point, dtype=np.float64)

    def cross(u: FloatArray, v: FloatArray, w: FloatArray) -> FloatArray:
        return (v[:, 0] - u[:, 0]) * (w[..., 1] - u[:, 1]) - (v[:, 1] - u[:, 1]) * (
            w[..., 0] - u[:, 0]
        )

    scale = np.abs(cross(a, b, c))
    tolerance = -1e-12 * scale
    inside = (
        (cross(a, b, p) >= tolerance)
        & (cross(b, c, p) >= tolerance)
        & (cross(c, a, p) >= tolerance)
    )
    found = np.flatnonzero(inside)
    return int(found[0]) if len(found) else -1


def _labels(
    mission: Mission, vertices: FloatArray, triangles: IntArray, shapes: list[Any]
) -> tuple[IntArray, tuple[tuple[str, ...], ...]]:
    """Each triangle's letter (the set of regions holding its centroid) and the letters,
    ordered by size, then by names."""
    centroids = _centroids(vertices, triangles)
    names = [r.name for r in mission.regions]
    tree = shapely.STRtree(shapes)
    hits = tree.query(shapely.points(centroids), predicate="within")
    tri_of, region_of = hits[0], hits[1]
    # Most triangles lie in at most one region: their letters come from numpy, only the
    # triangles in several regions (overlaps) are keyed one by one.
    count = np.bincount(tri_of, minlength=len(triangles))
    alone = count[tri_of] == 1
    single_region = np.zeros(len(triangles), dtype=np.int64)
    single_region[tri_of[alone]] = region_of[alone]
    single = np.flatnonzero(count == 1)
    # The regions holding some triangle alone, ascending, and each such triangle's rank among
    # them: np.unique's answer, by counting (region numbers are small) instead of sorting.
    single_of = single_region[single]
    present = np.bincount(single_of, minlength=len(names)) > 0
    used = np.flatnonzero(present)
    single_key = (np.cumsum(present, dtype=np.int64) - 1)[single_of]
    several: dict[int, list[str]] = {}
    for t, r in zip(tri_of[~alone].tolist(), region_of[~alone].tolist(), strict=True):
        several.setdefault(t, []).append(names[r])
    several_keys = {t: tuple(sorted(found)) for t, found in several.items()}
    # Ordered by size, then by names: the empty letter, the single regions by name, then
    # the overlaps (sorting plain names is cheaper than sorting keyed tuples).
    used_names = [names[r] for r in used.tolist()]
    single_names = sorted(set(used_names))
    ordered = [(), *((name,) for name in single_names)]
    ordered += sorted(set(several_keys.values()), key=lambda k: (len(k), k))
    # A single region's letter index: 1 + its name's rank among the single names.
    rank = {name: k for k, name in enumerate(single_names, start=1)}
    index = {key: k for k, key in enumerate(ordered)}
    letter_of = np.zeros(len(triangles), dtype=np.int64)  # index 0: the empty letter
    letter_of[single] = np.array([rank[name] for name in used_names], dtype=np.int64)[
        single_key.reshape(-1)
    ]
    for t, key in several_keys.items():
        letter_of[t] = index[key]
    return letter_of, tuple(ordered)


def _centroids(vertices: FloatArray, triangles: IntArray) -> FloatArray:
    """``vertices[triangles].mean(axis=1)``, the same floats: the mean over three corners
    adds them in order and divides by three, here without the (m, 3, 2) array of corners."""
    centroids = np.empty((len(triangles), 2))
    first, second, third = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    for axis in range(2):
        along = vertices[:, axis]
        centroids[:, axis] = (along[first] + along[second] + along[third]) / 3.0
    return centroids


def connected_components(neighbors: IntArray) -> IntArray:
    """Connected components of the triangle adjacency, numbered by their lowest triangle.

    That numbering is the one of a search started from each unlabelled triangle in index
    order (scipy's ``connected_components``), computed with numpy alone so that the stage
    does not import scipy (a fifth of a cold compile).  Union-find by hooking: every root
    points to the smallest root it shares an edge with, then paths are halved until every
    triangle points to its root; each round merges at least one pair of roots, so the loop
    ends, and on meshes it takes a handful of rounds.
    """
    count = len(neighbors)
    first = np.repeat(np.arange(count, dtype=np.int64), neighbors.shape[1] if count else 0)
    second = neighbors.reshape(-1).astype(np.int64, copy=False)
    keep = second >= 0  # -1: no neighbour across that side
    first, second = first[keep], second[keep]
    root = np.arange(count, dtype=np.int64)  # invariant: root[t] <= t
    while len(first):
        a, b = root[first], root[second]
        apart = a != b
        if not apart.any():
            break
        first, second, a, b = first[apart], second[apart], a[apart], b[apart]
        np.minimum.at(root, np.maximum(a, b), np.minimum(a, b))
        while True:
            jumped = root[root]
            if np.array_equal(jumped, root):
                break
            root = jumped
    # The root of a component is its lowest triangle: number components in that order (a
    # root's number is how many roots come before it; no sort of a million roots).
    is_root = root == np.arange(count, dtype=np.int64)
    number = np.cumsum(is_root, dtype=np.int64) - 1
    labels: IntArray = number[root]
    return labels


def build_abstraction(
    mission: Mission, layout: PlanningLayout | None = None, *, lines: Lines | None = None
) -> Abstraction:
    """Triangulate ``mission``'s workspace and build the transition system D.

    With a ``layout`` (a robot with a body, a margin), its free space and region shapes are
    triangulated and label the triangles instead of the mission's own. With ``lines``, a
    convex cells' mesh: every side extended across the free space (``"arrangement"``) or the
    reflex corners cut (``"reflex"``, ``"bisector"``), no inner points, and each triangle's
    face of that linework in ``stats["cell_faces"]`` (:mod:`tlmpc.abstraction.lines`).
    """
    started = time.perf_counter()
    # One geometry for planning and verifying: refuse what snapping to the grid would reshape.
    refuse_subgrid_features(mission)
    faces = None
    if lines is not None:
        from tlmpc.abstraction.triangulate import lines_mesh

        vertices, triangles, neighbors, shapes, faces = lines_mesh(mission, layout, lines)
    else:
        vertices, triangles, neighbors, shapes = triangulate(mission, layout)
    letter_of, letters = _labels(mission, vertices, triangles, shapes)
    # The lowest-numbered triangle holding the start exactly (a start on an edge or vertex
    # lies in several: the planner starts from any of them).
    cells = cells_in(vertices, triangles, neighbors, letter_of, mission.robot.start)
    start = min(c.triangle for c in cells) if cells else -1
    if start < 0:
        raise InvalidInputError(
            error(
                "A002",
                f"the start point {mission.robot.start} is not in the free workspace",
                hint="start the robot inside the boundary and outside every hole",
                file=mission.source,
                path="$.robot.start",
            )
        )
    component = connected_components(neighbors)
    corners = vertices[triangles]
    angles = _min_angle(corners)
    for array in (vertices, triangles, neighbors, letter_of, component):
        array.setflags(write=False)
    stats: dict[str, Any] = {
        "vertices": len(vertices),
        "triangles": len(triangles),
        "edges": int((neighbors >= 0).sum() // 2),
        "letters": len(letters),
        "components": int(component.max() + 1) if len(component) else 0,
        "min_angle_deg": round(float(angles.min()), 6) if len(angles) else None,
        "seconds": round(time.perf_counter() - started, 6),
        # the convex cells' mesh: the face of its arrangement each triangle lies in
        **({"cell_faces": faces} if faces is not None else {}),
    }
    return Abstraction(
        vertices=vertices,
        triangles=triangles,
        neighbors=neighbors,
        letter_of=letter_of,
        letters=letters,
        start=start,
        component=component,
        regions={r.name: r.polygon for r in mission.regions},
        stats=stats,
    )


def _min_angle(corners: FloatArray) -> FloatArray:
    """Each triangle's smallest angle in degrees.

    arccos is decreasing, so the smallest angle is the arccos of the largest cosine: one
    arccos per triangle instead of three, and each side's length computed once (a side's
    length does not depend on its direction), which gives the same floats.
    """
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab, bc, ca = b - a, c - b, a - c
    length_ab = np.linalg.norm(ab, axis=1)
    length_bc = np.linalg.norm(bc, axis=1)
    length_ca = np.linalg.norm(ca, axis=1)
    # the angle at a is between b - a and c - a (= -ca), and so on around the triangle
    cos_a = (ab * -ca).sum(axis=1) / (length_ab * length_ca)
    cos_b = (bc * -ab).sum(axis=1) / (length_bc * length_ab)
    cos_c = (ca * -bc).sum(axis=1) / (length_ca * length_bc)
    largest = np.maximum(np.maximum(cos_a, cos_b), cos_c)
    degrees: FloatArray = np.degrees(np.arccos(np.clip(largest, -1.0, 1.0)))
    return degrees


def abstraction_diagnostics(abstraction: Abstraction, mission: Mission) -> list[Diagnostic]:
    """Warnings: regions that got no triangle, regions unreachable from the start, a mesh far
    larger than the layout suggests."""
    # Which letters occur (anywhere, and in the start's component): counts, not a sort.
    letters = len(abstraction.letters)
    used = np.flatnonzero(np.bincount(abstraction.letter_of, minlength=letters)).tolist()
    joined = _touching_components(abstraction)
    near_start = abstraction.letter_of[joined == joined[abstraction.start]]
    reachable = np.flatnonzero(np.bincount(near_start, minlength=letters)).tolist()
    present = set(chain.from_iterable(map(abstraction.letters.__getitem__, used)))
    near = set(chain.from_iterable(map(abstraction.letters.__getitem__, reachable)))
    problems = []
    missing = [r for r in mission.regions if r.name not in present]
    unreachable = [r for r in mission.regions if r.name in present and r.name not in near]
    if len(missing) == 1:
        problems.append(
            Diagnostic(
                code="A010",
                severity="warning",
                file=mission.source,
                message=f"region {missing[0].name!r} got no triangle",
                hint="it lies outside the boundary or in holes, or is too thin to triangulate",
            )
        )
    elif missing:
        problems.append(
            Diagnostic(
                code="A010",
                severity="warning",
                file=mission.source,
                message=f"{len(missing)} regions got no triangle: "
                + _names([r.name for r in missing]),
                hint="they lie outside the boundary or in holes, or are too thin to triangulate",
            )
        )
    if len(unreachable) == 1:
        problems.append(
            Diagnostic(
                code="A011",
                severity="warning",
                file=mission.source,
                message=f"region {unreachable[0].name!r} is not reachable from "
                "the start: " + _separation(mission, unreachable[0].polygon),
                hint="open a passage or move the start",
            )
        )
    elif unreachable:
        # One warning for all (a map with pockets inside its racks has dozens): each name with
        # the piece it lies in.
        places = [_piece_of(mission, r.polygon) for r in unreachable]
        listed = _names(
            [
                f"{r.name} ({place})" if place else r.name
                for r, place in zip(unreachable, places, strict=True)
            ]
        )
        why = (
            "each lies in a separate piece of free space (a workspace component) that the "
            "robot cannot reach"
            if all(places)
            else "holes or separate pieces of free space keep the robot from them"
        )
        problems.append(
            Diagnostic(
                code="A011",
                severity="warning",
                file=mission.source,
                message=f"{len(unreachable)} regions are not reachable from the start: "
                f"{listed}; {why}",
                hint="open a passage or move the start",
            )
        )
    blowup = mesh_size_diagnostic(abstraction, mission)
    if blowup is not None:
        problems.append(blowup)
    return problems


def _names(names: list[str], shown: int = 12) -> str:
    """``a, b, c`` — the first ``shown`` of ``names`` and how many more."""
    if len(names) <= shown:
        return ", ".join(names)
    return ", ".join(names[:shown]) + f" and {len(names) - shown} more"


def _piece_of(mission: Mission, polygon: tuple[tuple[float, float], ...]) -> str | None:
    """``workspace component K`` when the region lies in a piece the robot is not in."""
    if not mission.workspace.components:
        return None
    from shapely.geometry import Point as ShapelyPoint
    from shapely.geometry import Polygon as ShapelyPolygon

    shape = ShapelyPolygon(polygon)
    start = ShapelyPoint(mission.robot.start)
    pieces = [ShapelyPolygon(p.boundary, p.holes) for p in mission.workspace.pieces]
    inside = [k for k, piece in enumerate(pieces) if piece.intersection(shape).area > 0]
    robot = next((k for k, piece in enumerate(pieces) if piece.covers(start)), None)
    if not inside or robot in inside:
        return None
    return ", ".join("the main piece" if k == 0 else f"workspace component {k - 1}" for k in inside)


def _touching_components(abstraction: Abstraction) -> Any:
    """Each triangle's component, with components that share a mesh vertex merged: pieces
    of free space that touch at a point are connected through it (a plan may pass through
    the point, see docs/planning.md), so a region beyond such a point is reachable.

    Each merged group is numbered by its lowest component.  Around each vertex every
    component is joined to the lowest one there (a scatter-minimum, no sort of the corners):
    the same groups as joining them in any other order.
    """
    component = np.asarray(abstraction.component, dtype=np.int64)
    count = int(component.max()) + 1 if len(component) else 0
    if count <= 1:
        return component
    corners = abstraction.triangles.reshape(-1)
    around = np.repeat(component, 3)
    lowest = np.full(len(abstraction.vertices), count, dtype=np.int64)
    np.minimum.at(lowest, corners, around)
    joined = lowest[corners] != around
    # Few pairs (one per component meeting another at a vertex): packed, then deduplicated.
    pairs = np.unique(lowest[corners][joined] * count + around[joined]).tolist()
    parent = list(range(count))

    def root(c: int) -> int:
        while parent[c] != c:
            parent[c] = parent[parent[c]]
            c = parent[c]
        return c

    for key in pairs:
        a, b = root(key // count), root(key % count)
        if a != b:
            parent[max(a, b)] = min(a, b)
    roots = np.array([root(c) for c in range(count)], dtype=np.int64)
    return roots[component]


def _separation(mission: Mission, polygon: tuple[tuple[float, float], ...]) -> str:
    """What separates a region from the robot, in the mission's terms."""
    if not mission.workspace.components:
        return "holes separate it from the robot"
    from shapely.geometry import Point as ShapelyPoint
    from shapely.geometry import Polygon as ShapelyPolygon

    shape = ShapelyPolygon(polygon)
    start = ShapelyPoint(mission.robot.start)
    pieces = [ShapelyPolygon(p.boundary, p.holes) for p in mission.workspace.pieces]
    inside = [k for k, piece in enumerate(pieces) if piece.intersection(shape).area > 0]
    robot = next((k for k, piece in enumerate(pieces) if piece.covers(start)), None)
    if inside and robot not in inside:
        names = ", ".join(
            "the main piece" if k == 0 else f"workspace component {k - 1}" for k in inside
        )
        return (
            f"it lies in {names}, a separate piece of free space that the robot "
            "(starting in "
            + ("the main piece" if robot == 0 else f"workspace component {(robot or 1) - 1}")
            + ") cannot reach"
        )
    return "holes separate it from the robot"


#: A mesh more than this many times the layout's corners is suspicious: clean maps and the
#: shipped missions give 2 to 5 triangles per corner of the workspace and regions.
MESH_BLOWUP_FACTOR = 20
#: ... and never below this many triangles (a small mission may refine freely).
MESH_BLOWUP_MIN = 2000


def _ring_area(ring: tuple[tuple[float, float], ...]) -> float:
    return abs(
        sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(ring, ring[1:] + ring[:1], strict=True))
        / 2.0
    )


def mesh_size_diagnostic(abstraction: Abstraction, mission: Mission) -> Diagnostic | None:
    """A warning (A012) when the mesh is far larger than the region layout suggests.

    The layout suggests about as many triangles as the workspace's and regions' corners (or
    the free area over ``max_area`` when that bound asks for more); far more means some
    feature much smaller than the rest forces the quality mesh to refine around it — most
    often a region corner or edge a hair (not exactly) on a wall.  The message names the
    shortest mesh edge and where it is, which is where that feature lies.
    """
    rings = [p.boundary for p in mission.workspace.pieces]
    rings += [h for p in mission.workspace.pieces for h in p.holes]
    corners = sum(len(ring) for ring in rings) + sum(len(r.polygon) for r in mission.regions)
    expected = float(corners)
    if mission.options.max_area:
        area = sum(_ring_area(p.boundary) for p in mission.workspace.pieces) - sum(
            _ring_area(h) for p in mission.workspace.pieces for h in p.holes
        )
        expected = max(expected, area / mission.options.max_area)
    count = abstraction.num_triangles
    if count <= max(MESH_BLOWUP_MIN, MESH_BLOWUP_FACTOR * expected):
        return None
    corners_xy = abstraction.vertices[abstraction.triangles]  # (n, 3, 2)
    sides = corners_xy[:, [1, 2, 0]] - corners_xy
    lengths = np.hypot(sides[..., 0], sides[..., 1])
    triangle, side = np.unravel_index(int(np.argmin(lengths)), lengths.shape)
    a = corners_xy[triangle, side]
    b = corners_xy[triangle, (side + 1) % 3]
    x, y = ((a + b) / 2).tolist()
    shortest = float(lengths[triangle, side])
    return Diagnostic(
        code="A012",
        severity="warning",
        file=mission.source,
        message=f"the mesh has {count:,} triangles, {count / expected:.0f} times what the "
        f"{corners:,} corners of the workspace and regions suggest: a feature as small as "
        f"{shortest:.2g} near ({x:.6g}, {y:.6g}) forces the refinement",
        hint="a region's corner or edge almost, but not exactly, on a wall or another "
        "region's edge leaves a sliver the mesh must fill: put it exactly on the edge "
        "(the same coordinates) or clearly away from it",
    )
