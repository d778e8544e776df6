"""A robot with a body on an occupancy map keeps off every occupied cell, specks included.

The importer drops obstacle pieces under ``min_area`` (sensor noise) for a point robot; a
body can hit an obstacle of three cells, so for a robot with a body every obstacle is kept.
The oracle is the image itself: the exact distance (shapely) from every segment of the
compiled trace to the box of every occupied cell.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
from robot_data import write_map

import tlmpc

RESOLUTION = 0.1
SPECK = [(15, 30), (15, 31), (14, 30)]  # (row, col) of a 3-cell obstacle, mid-map


def _map(tmp_path: Path) -> tuple[Path, np.ndarray[Any, np.dtype[np.bool_]]]:
    """A 6 x 3 room with a wall border and a 3-cell speck in the middle."""
    occupied = np.zeros((30, 60), dtype=bool)
    occupied[0, :] = occupied[-1, :] = occupied[:, 0] = occupied[:, -1] = True
    for row, col in SPECK:
        occupied[row, col] = True
    image = np.where(occupied, 0, 254).astype(np.uint8)
    return write_map(tmp_path, "room", image, resolution=RESOLUTION), occupied


def _cells(occupied: np.ndarray[Any, np.dtype[np.bool_]]) -> Any:
    rows, cols = np.nonzero(occupied)
    height = occupied.shape[0]
    x = cols * RESOLUTION
    y = (height - 1 - rows) * RESOLUTION
    return shapely.box(x, y, x + RESOLUTION, y + RESOLUTION)


@pytest.mark.parametrize(
    "body", [{"radius": 0.5}, {"footprint": [[-0.3, -0.3], [0.4, -0.3], [0.4, 0.3], [-0.3, 0.3]]}]
)
def test_the_body_stays_off_a_speck(tmp_path: Path, body: dict[str, Any]) -> None:
    path, occupied = _map(tmp_path)
    mission = {
        "version": 1,
        "workspace": {"map": str(path)},
        "regions": {"goal": {"rect": [5.0, 1.2, 5.6, 1.8]}},
        "robot": {"start": [0.8, 1.5], **body},
        "options": {"margin": 0},
        "task": ["visit goal"],
    }
    compiled = tlmpc.compile(mission)
    radius = compiled.artifacts["trace.json"]["radius"]
    points = np.asarray(compiled.artifacts["trace.json"]["points"], dtype=float)[:, 1:]
    segments = shapely.linestrings(np.stack([points[:-1], points[1:]], axis=1))
    tree = shapely.STRtree(_cells(occupied))
    _, distance = tree.query_nearest(segments, return_distance=True, all_matches=False)
    assert float(np.min(distance)) >= radius * (1 - 1e-9)


def test_a_point_robot_still_drops_specks(tmp_path: Path) -> None:
    """Without a body the speck is noise (``min_area``), as documented: no hole for it."""
    path, _ = _map(tmp_path)
    mission = {
        "version": 1,
        "workspace": {"map": str(path)},
        "regions": {"goal": {"rect": [5.0, 1.2, 5.6, 1.8]}},
        "robot": {"start": [0.8, 1.5]},
        "task": ["visit goal"],
    }
    compiled = tlmpc.compile(mission, until="abstraction")
    assert compiled.artifacts["mission.json"]["workspace"]["holes"] == []
