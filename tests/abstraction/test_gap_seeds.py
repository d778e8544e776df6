"""A body that closes a door splits the free space; the mesh keeps every piece.

Between the pieces of a split free space lies obstacle space that Triangle is told to carve
out by a seed point in it.  The gap between the convex hull and the pieces of a rotated map
holds rounding slivers along the hull's edges; a seed there lay a hair inside a piece, and
Triangle carved out the whole room (the start's: A002, "the start point is not in the free
workspace", for a start a metre from every wall).  The oracle is shapely's own erosion of
the map (area and pieces), which shares nothing with the mesh.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

import tlmpc
from tlmpc.abstraction.layout import planning_layout
from tlmpc.abstraction.triangulate import _hole_seed, triangulate
from tlmpc.mission.load import load_mission_text


def _two_rooms(angle: float, radius: float, door: float) -> str:
    """Two rooms of 4.5 x 6 and 5.4 x 6 joined by a door in a wall 0.1 thick, the whole map
    turned by ``angle`` about its centre; the start and the goal in the left room."""
    cos, sin = math.cos(angle), math.sin(angle)

    def turned(x: float, y: float) -> str:
        x, y = x - 5.0, y - 3.0
        return f"[{5.0 + x * cos - y * sin!r}, {3.0 + x * sin + y * cos!r}]"

    wall, thick, sill = 4.5, 0.1, 2.5
    outline = [
        (0, 0), (wall, 0), (wall, sill), (wall + thick, sill), (wall + thick, 0), (10, 0),
        (10, 6), (wall + thick, 6), (wall + thick, sill + door), (wall, sill + door),
        (wall, 6), (0, 6),
    ]  # fmt: skip
    boundary = ", ".join(turned(x, y) for x, y in outline)
    goal = ", ".join(turned(x, y) for x, y in [(0.4, 0.4), (1.4, 0.4), (1.4, 1.4), (0.4, 1.4)])
    return (
        "version: 1\n"
        f"workspace: {{boundary: [{boundary}]}}\n"
        f"regions: {{h: [{goal}]}}\n"
        f"robot: {{start: {turned(2.0, 3.0)}, radius: {radius!r}}}\n"
        "task: [visit h]\n"
        "options: {margin: 0.0}\n"
    )


def _check_pieces_meshed(text: str, radius: float) -> None:
    mission = load_mission_text(text)
    free = shapely.Polygon(mission.workspace.boundary)
    eroded = free.buffer(-radius, quad_segs=64)
    pieces = list(shapely.get_parts(eroded))
    assert len(pieces) == 2  # the body is wider than the door
    vertices, triangles, _, _ = triangulate(mission, planning_layout(mission, 0.0))
    corners = vertices[triangles]
    mesh_area = float(shapely.area(shapely.polygons(corners)).sum())
    assert mesh_area == pytest.approx(eroded.area, rel=1e-3)
    centroids = shapely.points(corners.mean(axis=1))
    for piece in pieces:
        assert shapely.contains(piece, centroids).sum() > 0


@pytest.mark.parametrize(
    ("angle", "radius", "door"),
    [
        (4.325638382299154, 0.2777842847958208, 0.5411940155944228),
        (4.701192087038066, 0.28855777801409904, 0.5553967328090373),
        (1.8071421258334888, 0.3565520935852337, 0.6872286969315303),
    ],
)
def test_a_room_beyond_a_closed_door_is_meshed(angle: float, radius: float, door: float) -> None:
    _check_pieces_meshed(_two_rooms(angle, radius, door), radius)


def test_random_turns_keep_both_rooms() -> None:
    rng = np.random.default_rng(7)
    for _ in range(12):
        radius = float(rng.uniform(0.2, 0.4))
        door = 2.0 * radius - float(rng.uniform(0.001, 0.1))
        angle = float(rng.uniform(0.0, 2.0 * math.pi))
        _check_pieces_meshed(_two_rooms(angle, radius, door), radius)


def test_the_start_beyond_the_sliver_compiles() -> None:
    # the found case: a start a metre from every wall was refused with A002
    text = _two_rooms(4.325638382299154, 0.2777842847958208, 0.5411940155944228)
    compiled = tlmpc.compile(text, until="abstraction")
    assert "R002" in [w.code for w in compiled.warnings]


def test_a_seed_lies_deep_inside_its_piece_not_in_its_sliver() -> None:
    # a room of obstacle space with a sliver a trillionth wide hanging from it: the
    # representative point lies in the sliver, a rounding error from the free space beside it
    piece = shapely.Polygon([(0, 0), (1e-12, 0), (1e-12, 9), (1, 9), (1, 10), (0, 10)])
    assert piece.boundary.distance(piece.representative_point()) < 1e-11
    point, depth = _hole_seed(piece, 1e-8)
    assert piece.contains(point)
    assert depth == pytest.approx(piece.boundary.distance(point))
    assert piece.boundary.distance(point) > 0.4  # the room is 1 wide
