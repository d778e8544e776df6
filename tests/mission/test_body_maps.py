"""Held-out real maps (nav2 occupancy grids): the robot's body stays off every occupied cell.

The mission takes its workspace from the map (``workspace: {map: ...}``) and the robot a
radius; start and goal are picked in the test's own configuration space (shapely buffer of
the imported free space).  The oracle reads the PGM itself and measures, with shapely, the
distance from every segment of the compiled trace to every cell that is not free (occupied
or unknown: the importer treats both as obstacles).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest
import shapely
import yaml
from robot_data import require_shared

import tlmpc
from tlmpc.importers.maps import ImportSettings, import_map

MARGIN = 0.1


def _pgm(path: Path) -> npt.NDArray[np.uint8]:
    """A binary (P5) 8-bit PGM as rows top to bottom."""
    data = path.read_bytes()
    fields: list[bytes] = []
    position = 0
    while len(fields) < 4:
        while data[position : position + 1].isspace():
            position += 1
        if data[position : position + 1] == b"#":
            position = data.index(b"\n", position) + 1
            continue
        end = position
        while not data[end : end + 1].isspace():
            end += 1
        fields.append(data[position:end])
        position = end
    assert fields[0] == b"P5"
    assert int(fields[3]) == 255
    width, height = int(fields[1]), int(fields[2])
    pixels = np.frombuffer(data, dtype=np.uint8, count=width * height, offset=position + 1)
    return pixels.reshape(height, width)


def _obstacle_cells(map_yaml: Path) -> Any:
    """Boxes of the non-free cells that border a free cell, in map coordinates."""
    meta = yaml.safe_load(map_yaml.read_text())
    image = _pgm(map_yaml.parent / meta["image"])
    shade = image.astype(float) / 255.0
    occupancy = shade if meta.get("negate", 0) else 1.0 - shade
    # every non-free cell: a robot with a body keeps even the specks (a body can hit them)
    free = occupancy < float(meta["free_thresh"])
    padded = np.pad(free, 1, constant_values=False)
    near_free = np.zeros_like(free)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            near_free |= padded[1 + dr : 1 + dr + free.shape[0], 1 + dc : 1 + dc + free.shape[1]]
    rows, cols = np.nonzero(~free & near_free)
    resolution = float(meta["resolution"])
    x0, y0 = float(meta["origin"][0]), float(meta["origin"][1])
    height = free.shape[0]
    xmin = x0 + cols * resolution
    ymin = y0 + (height - 1 - rows) * resolution
    return shapely.box(xmin, ymin, xmin + resolution, ymin + resolution)


def _pick(free: Any, radius: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """A start and a goal far apart in the largest part of the test's configuration space."""
    room = max(shapely.get_parts(free.buffer(-1.5 * radius)), key=lambda p: p.area)
    start = room.representative_point()
    inner = room.buffer(-0.2)
    inner = max(shapely.get_parts(inner), key=lambda p: p.area) if not inner.is_empty else room
    corners = shapely.get_coordinates(inner.exterior)
    far = corners[int(np.argmax(np.hypot(corners[:, 0] - start.x, corners[:, 1] - start.y)))]
    goal = shapely.Point(far)
    if not room.covers(goal):  # pragma: no cover - the corner of an eroded room lies in it
        goal = room.representative_point()
    return (start.x, start.y), (goal.x, goal.y)


@pytest.mark.slow
@pytest.mark.parametrize(("name", "radius"), [("depot", 0.2), ("warehouse", 0.25)])
def test_footprint_stays_off_real_map_obstacles(tmp_path: Path, name: str, radius: float) -> None:
    maps = require_shared("maps")
    map_yaml = maps / f"{name}.yaml"
    imported = import_map(map_yaml, ImportSettings(radius=0.0))
    free = shapely.Polygon(imported.boundary, list(imported.holes))
    free = shapely.make_valid(free)
    start, goal = _pick(free, radius)
    mission = {
        "version": 1,
        "workspace": {"map": str(map_yaml)},
        "regions": {"goal": {"rect": [goal[0] - 0.1, goal[1] - 0.1, goal[0] + 0.1, goal[1] + 0.1]}},
        "robot": {"start": list(start), "radius": radius},
        "task": ["visit goal"],
        "options": {"margin": MARGIN},
    }
    compiled = tlmpc.compile(mission)
    trace = compiled.artifacts["trace.json"]
    points = np.asarray(trace["points"], dtype=float)[:, 1:]
    segments = shapely.linestrings(np.stack([points[:-1], points[1:]], axis=1))
    cells = _obstacle_cells(map_yaml)
    tree = shapely.STRtree(cells)
    _, distance = tree.query_nearest(segments, return_distance=True, all_matches=False)
    assert float(np.min(distance)) >= radius
    # the mission's own obstacles (the imported polygons), as the verifier sees them
    assert tlmpc.verify_trace(trace).satisfied
    codes = {w.code for w in compiled.warnings}
    if "R008" not in codes:  # planned with the margin: kept from the cells themselves
        assert float(np.min(distance)) >= radius + MARGIN
        summary = compiled.summary["clearance"]
        assert summary["obstacles"] >= MARGIN
        depth = summary["depth"]["goal"]
        assert depth["achieved"] >= min(MARGIN, depth["inradius"] / 2) * (1 - 1e-9)
    assert "R006" not in codes or "R008" in codes
