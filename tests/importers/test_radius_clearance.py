"""`import-map --radius R` writes a configuration space: every point of the written workspace
keeps at least R cos(pi/32) from every non-free cell, however the simplification moved its
boundary (docs/robot-data.md, "Polygons", item 2).

The oracle reads the map YAML and its image on its own (nav2's trinary reading), unions the free
cells' squares in world coordinates with shapely, and measures the exact distance from the
written mission's workspace to everything else (the non-free cells and the outside of the map).
"""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
import yaml
from hypothesis import example, given
from hypothesis import strategies as st
from robot_data import image_from_free, require_shared, write_map
from shapely import affinity
from shapely.geometry import Polygon, box
from shapely.geometry.base import BaseGeometry

from tlmpc.cli import main

CLEARANCE = math.cos(math.pi / 32)


def run(*argv: str) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, err.getvalue()


def not_free(map_yaml: Path) -> BaseGeometry:
    """Everything but the free cells' squares, in world coordinates, from a trinary map."""
    from PIL import Image

    info = yaml.safe_load(map_yaml.read_text())
    assert info.get("mode", "trinary") == "trinary"
    pixels = np.asarray(Image.open(map_yaml.parent / info["image"]), dtype=np.float64)
    assert pixels.ndim == 2
    shade = pixels / 255.0
    occupancy = shade if info.get("negate", 0) else 1.0 - shade
    free = occupancy < float(info["free_thresh"])
    rows, cols = free.shape
    squares = []
    for row in range(rows):  # image row 0 is the top of the map
        y = rows - 1 - row
        run_start = None
        for col in range(cols + 1):
            inside = col < cols and bool(free[row, col])
            if inside and run_start is None:
                run_start = col
            elif not inside and run_start is not None:
                squares.append(box(run_start, y, col, y + 1))
                run_start = None
    cells = box(-2, -2, cols + 2, rows + 2).difference(shapely.union_all(squares))
    resolution = float(info["resolution"])
    x, y, yaw = (float(v) for v in info["origin"])
    world = affinity.scale(cells, resolution, resolution, origin=(0, 0))
    world = affinity.rotate(world, yaw, origin=(0, 0), use_radians=True)
    return affinity.translate(world, x, y)


def written_workspace(mission: dict[str, Any]) -> BaseGeometry:
    """The union of the written workspace's pieces (each an outer ring minus its holes)."""
    workspace = mission["workspace"]
    pieces = [Polygon(workspace["boundary"], workspace.get("holes") or [])]
    for component in workspace.get("components", []):
        pieces.append(Polygon(component["boundary"], component.get("holes") or []))
    assert all(p.is_valid for p in pieces)
    return shapely.union_all(pieces)


def clearance_of_import(map_yaml: Path, out: Path, radius: float, *flags: str) -> float | None:
    """The exact distance from the workspace ``import-map --radius`` writes to the non-free
    cells; None when the radius leaves no free space (M010)."""
    code, err = run("import-map", str(map_yaml), "--radius", repr(radius), *flags, "-o", str(out))
    if code == 2 and "error[M010]" in err:
        return None
    assert code == 0, err
    workspace = written_workspace(yaml.safe_load(out.read_text()))
    return float(workspace.distance(not_free(map_yaml)))


@pytest.mark.parametrize("radius", [0.1, 0.2, 0.35])
@pytest.mark.parametrize("name", ["tb3_sandbox", "smoothers_world"])
def test_real_maps_keep_the_radius_from_every_non_free_cell(
    tmp_path: Path, name: str, radius: float
) -> None:
    maps = require_shared("maps")
    distance = clearance_of_import(maps / f"{name}.yaml", tmp_path / "m.yaml", radius)
    assert distance is not None
    assert distance >= radius * CLEARANCE - 1e-9


@st.composite
def rooms(draw: st.DrawFn) -> np.ndarray:
    """A walled room with random blocks and single occupied cells (y-up rows)."""
    rows, cols = draw(st.integers(6, 16)), draw(st.integers(6, 16))
    free = np.ones((rows, cols), dtype=bool)
    free[0, :] = free[-1, :] = free[:, 0] = free[:, -1] = False
    for _ in range(draw(st.integers(0, 5))):
        r, c = draw(st.integers(0, rows - 1)), draw(st.integers(0, cols - 1))
        h, w = draw(st.integers(1, 4)), draw(st.integers(1, 4))
        free[r : r + h, c : c + w] = False
    return free


@pytest.mark.slow
@example(  # a pillar whose corner the one-cell simplification cut into by half the radius
    free=np.pad(np.pad(np.zeros((4, 2), dtype=bool), 3, constant_values=True), 1),
    radius=0.1,
    tolerance=None,
    yaw=0.0,
)
@example(  # a one-cell post, a hole smaller than the speck threshold once eroded by 0.02
    free=np.pad(np.pad(np.zeros((1, 1), dtype=bool), 4, constant_values=True), 1),
    radius=0.02,
    tolerance=0.0,
    yaw=0.0,
)
@given(
    free=rooms(),
    radius=st.floats(0.02, 0.3),
    tolerance=st.sampled_from([None, 0.0, 0.03, 0.1, 0.2]),
    yaw=st.sampled_from([0.0, 0.4, -2.0]),
)
def test_random_maps_keep_the_radius_from_every_non_free_cell(
    tmp_path_factory: pytest.TempPathFactory,
    free: np.ndarray,
    radius: float,
    tolerance: float | None,
    yaw: float,
) -> None:
    directory = tmp_path_factory.mktemp("room")
    path = write_map(directory, "m", image_from_free(free), resolution=0.1, origin=(1.0, -2.0, yaw))
    flags = [] if tolerance is None else ["--tolerance", repr(tolerance)]
    distance = clearance_of_import(path, directory / "mission.yaml", radius, *flags)
    if distance is not None:
        assert distance >= radius * CLEARANCE - 1e-9
