"""The reflex cuts' mesh (tlmpc.abstraction.lines): convex faces of one label set that cover
the free space exactly, checked with shapely on the raw geometry, independently of the mesh's
own bookkeeping.

* Per face (the triangles ``stats["cell_faces"]`` joins): one polygon, as large as its convex
  hull (convex); the faces' areas add up to the free space's, and their union is the free
  space (no overlap, no gap); every triangle of a face lies in the same regions, read off the
  mission's own region polygons with shapely (one label set).
* The convex cells of that mesh are exactly its faces.
* Random polygonal workspaces (star-shaped boundaries with reflex corners, star-shaped holes
  and regions that may overlap each other and the holes), a hypothesis property.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import shapely
import yaml
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon

import tlmpc.abstraction.lines
from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.lines import Lines, OverBudget, reflex_extensions
from tlmpc.base.errors import TlmpcError
from tlmpc.mission.load import load_mission_text
from tlmpc.mission.resolution import grid_size
from tlmpc.planning.cells import partition


def _faces_hold(document: dict[str, Any], kind: Lines = "reflex") -> int:
    """Check the ``kind`` cuts' mesh of ``document`` with shapely; the number of faces."""
    mission = load_mission_text(yaml.safe_dump(document), "<reflex>")
    mesh = build_abstraction(mission, lines=kind)
    corners = mesh.vertices[mesh.triangles]
    triangles = [Polygon(c) for c in corners.tolist()]
    boundary = Polygon(document["workspace"]["boundary"])
    holes = [Polygon(h) for h in document["workspace"].get("holes", [])]
    free = boundary.difference(shapely.union_all(holes)) if holes else boundary
    regions = {name: Polygon(points) for name, points in document["regions"].items()}
    # snapping to the grid moves a cut's end by up to a grid step off the side it ends on
    slack = free.length * grid_size(mission)
    faces: dict[int, list[int]] = {}
    for t, face in enumerate(mesh.stats["cell_faces"]):
        faces.setdefault(face, []).append(t)
    total = 0.0
    for members in faces.values():
        shape = shapely.union_all([triangles[t] for t in members])
        assert shape.geom_type == "Polygon", shape.geom_type
        assert shape.convex_hull.area - shape.area <= slack
        total += shape.area
        inside = {
            tuple(sorted(n for n, r in regions.items() if r.contains(triangles[t].centroid)))
            for t in members
        }
        assert len(inside) == 1, inside
    assert abs(total - free.area) <= slack
    union = shapely.union_all(triangles)
    assert union.symmetric_difference(free).area <= slack
    assert sum(t.area for t in triangles) == pytest.approx(union.area, rel=1e-9)
    # the convex cells of the mesh: convex, each inside one face (a face whose side a snapped
    # cut's end bends by more than the cells' collinearity tolerance is two cells)
    cells = partition(mesh)
    face_of = mesh.stats["cell_faces"]
    for cell in cells.cells:
        assert len({face_of[t] for t in cell.triangles}) == 1
        shape = shapely.union_all([triangles[t] for t in cell.triangles])
        assert shape.convex_hull.area - shape.area <= slack
    assert len(faces) <= len(cells.cells) <= 2 * len(faces)
    return len(faces)


def _room_grid(rows: int, columns: int) -> dict[str, Any]:
    regions = {
        f"r{i}_{j}": [
            [i + 0.25, j + 0.25],
            [i + 0.75, j + 0.25],
            [i + 0.75, j + 0.75],
            [i + 0.25, j + 0.75],
        ]
        for i in range(columns)
        for j in range(rows)
    }
    return {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [columns, 0], [columns, rows], [0, rows]]},
        "regions": regions,
        "robot": {"start": [0.1, 0.1], "max_speed": 1.0},
        "options": {"min_angle": None},
        "ltl": "F r0_0",
    }


def test_a_grid_of_rooms_is_cut_into_its_grid() -> None:
    """Rooms on a grid (Example 8's layout): every cut runs from a room's corner to the next
    room's, so the faces are the grid's rectangles: (2 x 3 + 1) x (2 x 2 + 1) of them. Cut by
    bisectors alone the grid's faces are fewer and not all rectangles."""
    assert _faces_hold(_room_grid(2, 3)) == 7 * 5
    assert _faces_hold(_room_grid(2, 3), "bisector") != 7 * 5


@pytest.mark.parametrize("kind", ["reflex", "bisector"])
def test_an_l_shaped_room_with_a_region_across_its_corner(kind: Lines) -> None:
    document = {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [6, 0], [6, 2], [2, 2], [2, 6], [0, 6]]},
        "regions": {
            "a": [[1, 1], [3, 1], [3, 2], [2, 2], [2, 3], [1, 3]],
            "b": [[4, 0.5], [5, 1.5], [4, 1.5]],
        },
        "robot": {"start": [0.5, 0.5], "max_speed": 1.0},
        "ltl": "F a",
    }
    _faces_hold(document, kind)


def test_a_shallow_reflex_corner_is_cut_by_its_bisector() -> None:
    """A corner of 190 degrees: extending its sides would make two 10-degree corners; the
    bisector makes two of 95."""
    document = {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [10, 0], [10, 4], [5, 3.563], [0, 4]]},
        "regions": {"a": [[8, 1], [9, 1], [9, 2], [8, 2]]},
        "robot": {"start": [0.5, 0.5], "max_speed": 1.0},
        "ltl": "F a",
    }
    assert _faces_hold(document) >= 2
    mission = load_mission_text(yaml.safe_dump(document), "<reflex>")
    mesh = build_abstraction(mission, lines="reflex")
    angles = _face_angles(mesh)
    assert min(angles) > 20.0


def _face_angles(mesh: Any) -> list[float]:
    found = []
    faces: dict[int, list[int]] = {}
    for t, face in enumerate(mesh.stats["cell_faces"]):
        faces.setdefault(face, []).append(t)
    for members in faces.values():
        shape = shapely.union_all([Polygon(mesh.vertices[mesh.triangles[t]]) for t in members])
        ring = np.asarray(shape.simplify(0.0).exterior.coords)[:-1]
        for k in range(len(ring)):
            a, b, c = ring[k - 1], ring[k], ring[(k + 1) % len(ring)]
            u, v = a - b, c - b
            cos = float(u @ v / (np.linalg.norm(u) * np.linalg.norm(v)))
            found.append(math.degrees(math.acos(max(-1.0, min(1.0, cos)))))
    return found


def test_the_budget_counts_work_not_time(monkeypatch: pytest.MonkeyPatch) -> None:
    mission = load_mission_text(yaml.safe_dump(_room_grid(3, 3)), "<grid>")
    free = shapely.Polygon([(0, 0), (3, 0), (3, 3), (0, 3)])
    rooms = [shapely.Polygon(r.polygon).boundary for r in mission.regions]
    linework = shapely.union_all([free.boundary, *rooms])
    cuts = reflex_extensions(linework, free)
    assert cuts.segments is not None
    assert cuts.corners == 4 * 9  # every room's corners, seen from the space between them
    # the work: a unit per corner, at least three per ray shot (the two sides through its
    # corner touch it, and what it hits), and one per pair of cuts that meet (brute force)
    rays = 2 * cuts.corners  # both sides of a right-angled reflex corner go on
    meeting = sum(
        1
        for i, first in enumerate(cuts.segments)
        for second in cuts.segments[i + 1 :]
        if first.intersects(second)
    )
    assert cuts.work >= cuts.corners + 3 * rays + meeting
    again = reflex_extensions(linework, free, budget=cuts.work - 1)
    assert again.segments is None
    assert reflex_extensions(linework, free, budget=cuts.work).segments is not None
    monkeypatch.setattr(tlmpc.abstraction.lines, "MAX_REFLEX_WORK", 10)
    with pytest.raises(OverBudget):
        build_abstraction(mission, lines="reflex")


def _star(draw: st.DrawFn, cx: int, cy: int, low: int, high: int) -> list[list[float]]:
    """A star-shaped polygon about (cx, cy) on a lattice of tenths (reflex corners likely)."""
    count = draw(st.integers(3, 8))
    turns = sorted(draw(st.lists(st.integers(0, 359), min_size=count, max_size=count, unique=True)))
    points = []
    for turn in turns:
        radius = draw(st.integers(low, high))
        x = round(cx + radius * math.cos(math.radians(turn))) / 10.0
        y = round(cy + radius * math.sin(math.radians(turn))) / 10.0
        points.append([x, y])
    return points


@st.composite
def workspaces(draw: st.DrawFn) -> dict[str, Any]:
    boundary = _star(draw, 100, 100, 40, 100)
    outline = Polygon(boundary)
    assume(outline.is_valid and outline.area > 50.0)
    holes: list[list[list[float]]] = []
    for _ in range(draw(st.integers(0, 2))):
        hole = _star(draw, draw(st.integers(50, 150)), draw(st.integers(50, 150)), 5, 20)
        shape = Polygon(hole)
        if (
            shape.is_valid
            and shape.area > 0.5
            and outline.buffer(-0.2).contains(shape)
            and all(not Polygon(h).buffer(0.2).intersects(shape) for h in holes)
        ):
            holes.append(hole)
    regions = {}
    for k in range(draw(st.integers(1, 3))):
        region = _star(draw, draw(st.integers(50, 150)), draw(st.integers(50, 150)), 10, 40)
        shape = Polygon(region)
        if shape.is_valid and shape.area > 0.5 and outline.contains(shape):
            regions[f"r{k}"] = region
    assume(regions)
    free = outline.difference(shapely.union_all([Polygon(h) for h in holes]))
    start = free.representative_point()
    assume(all(not Polygon(r).boundary.distance(start) < 1e-3 for r in regions.values()))
    return {
        "version": 1,
        "workspace": {"boundary": boundary, "holes": holes},
        "regions": regions,
        "robot": {"start": [start.x, start.y], "max_speed": 1.0},
        "options": {"min_angle": None},
        "ltl": "F " + sorted(regions)[0],
    }


def _drawn(
    boundary: list[list[float]], hole: list[list[float]], region: list[list[float]]
) -> dict[str, Any]:
    start = Polygon(boundary).difference(Polygon(hole)).representative_point()
    return {
        "version": 1,
        "workspace": {"boundary": boundary, "holes": [hole]},
        "regions": {"r0": region},
        "robot": {"start": [start.x, start.y], "max_speed": 1.0},
        "options": {"min_angle": None},
        "ltl": "F r0",
    }


#: A region whose corner touches a hole's corner: the face around them has two rings meeting
#: at that point, and a ray the region's ring shoots from its corner runs into the hole.
TOUCHING_AT_A_CORNER = _drawn(
    [[14.2, 10.0], [14.1, 10.1], [8.5, 19.5], [9.2, 0.7]],
    [[11.7, 5.8], [11.7, 5.8], [12.4, 7.1], [10.6, 5.0], [10.4, 4.3], [11.3, 5.4]],
    [[11.2, 5.8], [9.0, 7.2], [10.6, 5.0]],
)
#: A region across a hole's side: the side is noded where the region's side crosses it and
#: the region's side clipped there, a pixel apart (a one-pixel segment, a needle triangle).
CROSSING_A_HOLE = _drawn(
    [[14.0, 10.0], [14.2, 10.1], [9.1, 18.2], [7.8, 0.4]],
    [[10.7, 5.3], [10.7, 5.3], [10.7, 5.3], [10.7, 5.3], [9.9, 6.0], [9.4, 6.0], [9.7, 5.3]],
    [[10.1, 5.9], [9.1, 5.8], [10.7, 4.9]],
)


@pytest.mark.parametrize("document", [TOUCHING_AT_A_CORNER, CROSSING_A_HOLE])
@pytest.mark.parametrize("kind", ["reflex", "bisector"])
def test_cuts_stay_out_of_holes_and_regions_at_pinched_corners(
    document: dict[str, Any], kind: Lines
) -> None:
    _faces_hold(document, kind)


def test_no_needle_where_a_region_crosses_a_hole() -> None:
    """The plain mesh too: no triangle thinner than the grid where the region's side meets
    the hole's (the two snapped crossings are one vertex)."""
    mission = load_mission_text(yaml.safe_dump(CROSSING_A_HOLE), "<crossing>")
    mesh = build_abstraction(mission)
    corners = mesh.vertices[mesh.triangles]
    first, second = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    doubled = np.abs(first[:, 0] * second[:, 1] - first[:, 1] * second[:, 0])
    longest = np.max(np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2), axis=1)
    # the height over the longest side: a needle's is below a few grid steps
    assert np.min(doubled / longest) > 10 * grid_size(mission)


@pytest.mark.slow
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(workspaces())
def test_reflex_faces_are_convex_labelled_and_cover_the_free_space(
    document: dict[str, Any],
) -> None:
    try:
        load_mission_text(yaml.safe_dump(document), "<reflex>")
    except TlmpcError:
        assume(False)  # an input the loader refuses (a sliver, a start on a side): not ours
    _faces_hold(document, "reflex")
    _faces_hold(document, "bisector")


def test_reflex_cell_moves_state_the_rows_optimum() -> None:
    """On the reflex cuts' cells of an L-shaped room with an L-shaped region across its corner
    (T-junctions where cuts end on the region's sides), every move's stated width is the
    optimum of its rows at its xi: an independent second-order cone program (cvxpy) over the
    cell's polygon, rebuilt here from the boundary's vertices and the sides the move keeps."""
    import cvxpy as cp

    document = {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [6, 0], [6, 2], [2, 2], [2, 6], [0, 6]]},
        "regions": {"a": [[1, 1], [3, 1], [3, 2], [2, 2], [2, 3], [1, 3]]},
        "robot": {"start": [0.5, 0.5], "max_speed": 1.0},
        "ltl": "F a",
    }
    mission = load_mission_text(yaml.safe_dump(document), "<reflex>")
    cells = partition(build_abstraction(mission, lines="reflex"))
    points = cells.abstraction.vertices
    checked = 0
    for cell in cells.cells:
        for target in sorted({s.neighbour for s in cell.sides if s.neighbour >= 0}):
            move = cells.move(cell.index, target)
            if move.width <= 0.0 or checked >= 16:
                continue
            rows: dict[int, list[np.ndarray]] = {v: [] for v in cell.boundary}
            for k in move.kept:
                side = cell.sides[k]
                a, b = points[side.start], points[side.end]
                normal = np.array([a[1] - b[1], b[0] - a[0]]) / math.dist(a.tolist(), b.tolist())
                rows[side.start].append(normal)
                rows[side.end].append(normal)
            d = cp.Variable()
            constraints = []
            for normals in rows.values():
                u = cp.Variable(2)
                constraints.append(cp.norm(u) <= 1.0)
                constraints += [n @ u >= d for n in [*normals, np.asarray(move.xi)]]
            cp.Problem(cp.Maximize(d), constraints).solve()
            assert float(d.value) == pytest.approx(move.width, abs=1e-6)
            checked += 1
    assert checked >= 10
