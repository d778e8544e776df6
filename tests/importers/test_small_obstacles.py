"""Obstacles of at least ``min_area`` cells survive the import's simplification; smaller ones
are filled; the written workspace stays within the tolerance of the exact cell union.

Simplification within one cell takes a 4-cell L, S or T obstacle to a triangle of 3 cells or
less, so an obstacle judged by its simplified area was filled as a speck: occupied cells were
written out as free space.  Oracle: shapely's union of the free cells' squares, with the holes
smaller than ``min_area`` filled, compared by Hausdorff distance and by overlap.
"""

from __future__ import annotations

import io
import tempfile
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from robot_data import image_from_free, write_map
from shapely.geometry import Point, Polygon

from tlmpc.cli import main
from tlmpc.importers import maps
from tlmpc.importers.maps import ImportSettings, _obstacles_kept, import_map

Cells = frozenset[tuple[int, int]]


def _normal(cells: Cells) -> Cells:
    low_r = min(r for r, _ in cells)
    low_c = min(c for _, c in cells)
    return frozenset((r - low_r, c - low_c) for r, c in cells)


def _shapes(largest: int) -> list[Cells]:
    """Every fixed polyomino of 1..``largest`` cells (each rotation and reflection its own)."""
    found: set[Cells] = {frozenset({(0, 0)})}
    layer = set(found)
    for _ in range(largest - 1):
        grown = {
            _normal(shape | {(r + dr, c + dc)})
            for shape in layer
            for r, c in shape
            for dr, dc in ((0, 1), (1, 0), (0, -1), (-1, 0))
            if (r + dr, c + dc) not in shape
        }
        found |= grown
        layer = grown
    return sorted(found, key=sorted)


#: 1 + 2 + 6 + 19 + 63 shapes: specks of 1..3 cells, every tetromino (L, T, S, I, square)
#: and pentomino in every orientation.
SHAPES = _shapes(5)
SIZE = 16
blobs = st.lists(
    st.tuples(st.sampled_from(SHAPES), st.integers(2, SIZE - 3), st.integers(2, SIZE - 3)),
    min_size=1,
    max_size=6,
)


def _squares(mask: np.ndarray) -> shapely.Geometry:
    rows, cols = np.nonzero(mask)
    return shapely.union_all(shapely.box(cols, rows, cols + 1, rows + 1))


def test_the_shape_catalogue_is_complete() -> None:
    assert [sum(len(s) == n for s in SHAPES) for n in range(1, 6)] == [1, 2, 6, 19, 63]


@given(
    placed=blobs,
    tolerance=st.sampled_from([0.5, 1.0]),
    min_cells=st.sampled_from([None, 2.0, 5.0]),
    keepout=st.booleans(),
)
@settings(max_examples=80, deadline=None)
def test_obstacles_of_min_area_survive_and_specks_are_filled(
    placed: list[tuple[Cells, int, int]], tolerance: float, min_cells: float | None, keepout: bool
) -> None:
    free = np.ones((SIZE, SIZE), dtype=bool)
    free[[0, -1], :] = free[:, [0, -1]] = False
    for shape, r0, c0 in placed:
        for r, c in shape:
            # rows and columns 1 and SIZE - 2 stay free: one main piece round every blob
            free[min(r0 + r, SIZE - 3), min(c0 + c, SIZE - 3)] = False
    min_area = 4.0 if min_cells is None else min_cells
    with tempfile.TemporaryDirectory() as folder:
        path = write_map(Path(folder), "m", image_from_free(free), resolution=1.0)
        masks = {}
        if keepout:
            # a keepout band across the middle: its edges are noded with the obstacles'
            marked = np.zeros_like(free)
            marked[SIZE // 2 - 2 : SIZE // 2 + 1, :] = True
            masks["keepout"] = write_map(
                Path(folder), "k", image_from_free(~marked), resolution=1.0
            )
        imported = import_map(
            path,
            ImportSettings(tolerance=tolerance, min_area=min_cells, start=(1.5, 1.5)),
            **masks,
        )
    written = Polygon(imported.boundary, imported.holes)
    assert written.is_valid
    exact = _squares(free)
    main_piece = next(p for p in getattr(exact, "geoms", [exact]) if p.covers(Point(1.5, 1.5)))
    obstacles = [Polygon(ring) for ring in main_piece.interiors]
    kept = [h for h in obstacles if h.area >= min_area]
    specks = [h for h in obstacles if h.area < min_area]
    expected = Polygon(main_piece.exterior, [h.exterior for h in kept])
    slack = tolerance + 1e-9
    # (b) the written boundary is within the tolerance of the exact one and vice versa
    distance = shapely.hausdorff_distance(written.boundary, expected.boundary, densify=0.05)
    assert distance <= slack, (distance, [len(h) for h in (written.interiors, kept)])
    # (a) every obstacle of min_area is still one: it keeps a hole of its own, and free space
    # written over its cells lies within the tolerance of its edge
    assert len(written.interiors) == len(kept)
    for hole in kept:
        assert hole.difference(written).area > 0
        assert written.intersection(hole).difference(hole.exterior.buffer(slack)).area < 1e-9
    # (c) a speck's cells are free space, but where the tolerance lets the boundary cut in
    for speck in specks:
        assert speck.difference(written).difference(expected.boundary.buffer(slack)).area < 1e-9
    assert imported.speckles_dropped == len(specks)


def test_a_t_shaped_obstacle_of_four_cells_is_kept(tmp_path: Path) -> None:
    """A 12 x 12 map at 0.05 m: a T of 4 occupied cells amid free space, the default
    tolerance (one cell) and minimum area (4 cells)."""
    free = np.ones((12, 12), dtype=bool)
    free[[0, -1], :] = free[:, [0, -1]] = False
    free[6, 5:8] = False  # the T's bar
    free[5, 6] = False  # its stem
    path = write_map(tmp_path, "t", image_from_free(free), resolution=0.05)
    imported = import_map(path)
    assert len(imported.holes) == 1
    hole = Polygon(imported.holes[0])
    obstacle = shapely.affinity.scale(_squares(~free[1:-1, 1:-1]), 0.05, 0.05, origin=(0, 0))
    obstacle = shapely.affinity.translate(obstacle, 0.05, 0.05)
    assert shapely.hausdorff_distance(hole.boundary, obstacle.boundary, densify=0.005) <= 0.05
    # never more free space than the free cells plus the tolerance's worth round the T
    assert imported.workspace_area < imported.free_cells_area + 0.05 * obstacle.length / 2
    out = tmp_path / "t.mission.yaml"
    code = main(["import-map", str(path), "-q", "-o", str(out)], io.StringIO(), io.StringIO())
    assert code == 0
    assert "holes: []" not in out.read_text()


@pytest.mark.parametrize("cells", [3, 4])
def test_the_threshold_is_the_exact_cell_area(tmp_path: Path, cells: int) -> None:
    """An L of 3 cells is a speck under the default minimum area; an L of 4 is not (this one
    used to be simplified to 2 cells' area and filled)."""
    free = np.ones((10, 10), dtype=bool)
    free[[0, -1], :] = free[:, [0, -1]] = False
    free[[4, 5], 5] = False
    free[5, 4] = False
    if cells == 4:
        free[3, 5] = False
    path = write_map(tmp_path, "l", image_from_free(free), resolution=0.1)
    imported = import_map(path)
    assert len(imported.holes) == (cells >= 4)
    assert imported.speckles_dropped == (cells < 4)


def test_a_free_pocket_of_four_cells_is_a_component(tmp_path: Path) -> None:
    """Free pieces too are judged by their cells: an S of 4 free cells behind a wall is a
    further component (it used to be simplified to less than 4 cells' area and dropped)."""
    free = np.zeros((10, 16), dtype=bool)
    free[1:9, 1:9] = True  # the room
    free[4, 11:13] = free[5, 12:14] = True  # the pocket
    path = write_map(tmp_path, "s", image_from_free(free), resolution=0.1)
    imported = import_map(path)
    assert len(imported.components) == 1
    ((outer, _),) = imported.components
    pocket = shapely.affinity.scale(_squares(free[:, 10:]), 0.1, 0.1, origin=(0, 0))
    pocket = shapely.affinity.translate(pocket, 1.0, 0.0)
    assert shapely.hausdorff_distance(Polygon(outer).boundary, pocket.boundary) <= 0.1 + 1e-9


def test_an_obstacle_lost_to_simplification_is_noticed() -> None:
    """Simplified faces take the label of the exact face they overlap most: a hole simplified
    to a sliver over free cells would be labelled free.  The check that makes the import keep
    the exact faces then must see that the hole is gone."""
    room = Polygon([(0, 0), (10, 0), (10, 10), (0, 10)], [[(4, 4), (6, 4), (6, 6), (4, 4)]])
    assert _obstacles_kept(room, [Polygon([(4, 4), (6, 4), (6, 6)])])
    assert not _obstacles_kept(room, [])
    assert not _obstacles_kept(room, [Polygon([(7, 7), (8, 7), (8, 8)])])
    assert not _obstacles_kept(room, [Polygon([(6, 6), (7, 6), (7, 7)])])  # touching only
    assert _obstacles_kept(Polygon(room.exterior), [])


def test_a_free_pocket_inside_an_obstacle_is_not_taken_for_the_main_piece(tmp_path: Path) -> None:
    """The pocket's bounding box lies inside the room's: each exact piece must be matched to
    the simplified piece it overlaps most, not merely to one near it."""
    free = np.zeros((10, 10), dtype=bool)
    free[1:9, 1:9] = True  # the room
    free[2:8, 2:8] = False  # a block of shelving
    free[4, 4:6] = free[5, 5:7] = True  # a pocket of 4 free cells inside it
    path = write_map(tmp_path, "p", image_from_free(free), resolution=1.0)
    imported = import_map(path)
    assert Polygon(imported.boundary).equals(shapely.box(1, 1, 9, 9))
    assert len(imported.holes) == 1
    assert len(imported.components) == 1
    assert Polygon(imported.components[0][0]).within(shapely.box(4, 4, 7, 6))


def test_an_obstacle_whose_simplified_hole_moved_off_it_keeps_its_exact_shape(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Simplification within the tolerance does not do this, but should a simplified hole end
    up over free cells it would be labelled free: the import then keeps the exact faces."""
    free = np.ones((12, 12), dtype=bool)
    free[[0, -1], :] = free[:, [0, -1]] = False
    free[6, 5:8] = free[5, 6] = False  # a T of 4 cells
    exact_simplified = maps._simplified

    def moved(noded: shapely.Geometry, tolerance: float, rounds: int = 8) -> shapely.Geometry:
        chains = list(exact_simplified(noded, tolerance, rounds).geoms)
        hole = min(range(len(chains)), key=lambda k: chains[k].length)
        chains[hole] = shapely.LineString([(2, 2), (3, 2), (2, 3), (2, 2)])  # over free cells
        return shapely.MultiLineString(chains)

    monkeypatch.setattr(maps, "_simplified", moved)
    path = write_map(tmp_path, "t", image_from_free(free), resolution=1.0)
    imported = import_map(path)
    assert len(imported.holes) == 1
    obstacle = shapely.affinity.translate(_squares(~free[1:-1, 1:-1]), 1, 1)
    assert Polygon(imported.holes[0]).equals(obstacle)
