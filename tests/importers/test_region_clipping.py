"""`import-map --region`: rectangles clipped to the eroded workspace share its vertices exactly,
so the mesh stays the size of a clean import (no sliver between a region and a wall).

Oracles: shapely (the region lies in the workspace; the clipped region is the rectangle's
intersection with it up to the snapping tolerance), exact coordinate equality for the shared
vertices, and the mesh of the same map without the region (a clean import).
"""

from __future__ import annotations

import io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from robot_data import image_from_free, require_shared, write_map
from shapely.geometry import Polygon, box

from tlmpc.cli import main


def _run(*argv: str) -> tuple[int, str]:
    err = io.StringIO()
    code = main(list(argv), out=io.StringIO(), err=err)
    return code, err.getvalue()


def _pillars_map(directory: Path) -> Path:
    """A 6 x 6 m room (0.05 m cells) with round pillars and a slanted wall: eroded by a radius,
    its boundary has arcs and oblique edges a rectangle crosses at computed points."""
    n = 120
    ys, xs = np.mgrid[0:n, 0:n]
    free = np.ones((n, n), dtype=bool)
    free[[0, -1], :] = free[:, [0, -1]] = False
    for cx, cy, r in ((30, 30, 8), (80, 40, 10), (60, 90, 7)):
        free[(xs - cx) ** 2 + (ys - cy) ** 2 <= r * r] = False
    free[xs + ys < 25] = False  # a slanted corner
    return write_map(directory, "room", image_from_free(free), resolution=0.05)


def _triangles(mission: Path, out: Path) -> int:
    code, err = _run("compile", str(mission), "-o", str(out), "--until", "abstraction", "-q")
    assert code == 0, err
    return len(json.loads((out / "abstraction.json").read_text())["triangles"])


def _ring_vertices(document: dict[str, Any]) -> set[tuple[float, float]]:
    workspace = document["workspace"]
    rings = [workspace["boundary"], *workspace.get("holes", [])]
    return {(float(x), float(y)) for ring in rings for x, y in ring}


@pytest.fixture(scope="module")
def room(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _pillars_map(tmp_path_factory.mktemp("room"))


@given(
    x0=st.floats(0.0, 5.5),
    y0=st.floats(0.0, 5.5),
    width=st.floats(0.2, 6.0),
    height=st.floats(0.2, 6.0),
)
@settings(
    max_examples=12,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
def test_a_clipped_rectangle_shares_the_workspace_vertices(
    room: Path, tmp_path: Path, x0: float, y0: float, width: float, height: float
) -> None:
    rect = (x0, y0, min(x0 + width, 6.0), min(y0 + height, 6.0))
    mission = tmp_path / "m.yaml"
    code, err = _run(
        "import-map", str(room), "--radius", "0.2", "--region", "r", *map(repr, rect),
        "--task", "visit r", "-o", str(mission),
    )  # fmt: skip
    if code != 0:
        assert "M017" in err  # the rectangle misses the free space
        return
    document = yaml.safe_load(mission.read_text())
    region = [(float(x), float(y)) for x, y in document["regions"]["r"]]
    workspace = document["workspace"]
    outer = Polygon(workspace["boundary"])
    free = Polygon(workspace["boundary"], workspace.get("holes", []))
    shape = Polygon(region)
    assert shape.is_valid
    assert outer.covers(shape)
    # the clipped rectangle, up to the snapping tolerance
    expected = box(*rect).intersection(outer)
    assert shape.symmetric_difference(expected).area <= 1e-6 * max(expected.area, 1e-9)
    # every vertex is a workspace vertex exactly, or clearly away from every ring
    shared = _ring_vertices(document)
    rings = [workspace["boundary"], *workspace.get("holes", [])]
    lines = [Polygon(r).exterior for r in rings]
    for vertex in region:
        if vertex in shared:
            continue
        distance = min(line.distance(Polygon([vertex, vertex, vertex]).centroid) for line in lines)
        assert distance > 1e-9 * 6.0, vertex
    assert free.intersection(shape).area > 0


def test_the_mesh_of_a_clipped_region_stays_the_size_of_a_clean_import(
    room: Path, tmp_path: Path
) -> None:
    clean = tmp_path / "clean.yaml"
    # the clean import: a region far inside the free space, touching no wall
    assert _run(
        "import-map", str(room), "--radius", "0.2", "--region", "c", "2.6", "2.6", "2.8", "2.8",
        "--task", "visit c", "-o", str(clean),
    )[0] == 0  # fmt: skip
    reference = _triangles(clean, tmp_path / "clean")
    for index, rect in enumerate(
        [(0, 0, 3, 3), (1.5, -1, 6, 2.1), (-1, 1.45, 7, 2.05), (2.9, 0, 3.3, 6)]
    ):
        mission = tmp_path / f"m{index}.yaml"
        assert _run(
            "import-map", str(room), "--radius", "0.2", "--region", "r", *map(str, rect),
            "--task", "visit r", "-o", str(mission),
        )[0] == 0  # fmt: skip
        assert _triangles(mission, tmp_path / f"out{index}") <= 3 * reference


def test_the_real_sandbox_map_with_regions_crossing_its_walls(tmp_path: Path) -> None:
    # nav2's TurtleBot3 sandbox eroded by 0.2 m: each of these rectangles crosses its outer
    # wall; clipped with a hair's margin (the old way) they made meshes of 30,000 triangles
    sandbox = require_shared("maps/tb3_sandbox.yaml")
    clean = tmp_path / "clean.yaml"
    assert _run(
        "import-map", str(sandbox), "--radius", "0.2", "--region", "c", "1", "-1", "2", "0",
        "--task", "visit c", "-o", str(clean),
    )[0] == 0  # fmt: skip
    reference = _triangles(clean, tmp_path / "clean")
    for index, rect in enumerate(
        [(-3, -3, 0, 0), (0, 0, 3, 3), (-1.2, -3, -0.8, 3), (1.5, -3, 3, 3)]
    ):
        mission = tmp_path / f"m{index}.yaml"
        assert _run(
            "import-map", str(sandbox), "--radius", "0.2", "--region", "a", *map(str, rect),
            "--task", "visit a", "-o", str(mission),
        )[0] == 0  # fmt: skip
        count = _triangles(mission, tmp_path / f"out{index}")
        assert count <= 3 * reference, (rect, count, reference)


def test_a_mesh_far_larger_than_the_layout_is_warned_about(tmp_path: Path) -> None:
    # a region whose edge runs a micrometre inside the wall: a sliver the mesh must fill
    mission = tmp_path / "m.yaml"
    hair = "1.0e-6"
    mission.write_text(
        "version: 1\nworkspace:\n  boundary: [[0, 0], [4, 0], [4, 4], [0, 4]]\n"
        f"regions:\n  strip: [[{hair}, 1], [2, 1], [2, 3], [{hair}, 3]]\n"
        "robot: {start: [3, 3]}\ntask: [visit strip]\n"
        # the region's own shape is meshed (a visited region's core would miss the sliver)
        "options: {goal_depth: 0}\n"
    )
    out = io.StringIO()
    err = io.StringIO()
    code = main(
        ["compile", str(mission), "-o", str(tmp_path / "out"), "--until", "abstraction"], out, err
    )
    assert code == 0
    text = err.getvalue()
    assert "warning[A012]" in text
    found = text.split("near (", 1)[1].split(")", 1)[0]
    x, y = (float(v) for v in found.split(","))
    assert x < 1e-3  # at the sliver, by the left wall
    assert 0.99 <= y <= 3.01
    # the same region exactly on the wall: no warning
    mission.write_text(mission.read_text().replace(hair, "0"))
    err = io.StringIO()
    assert (
        main(
            ["compile", str(mission), "-o", str(tmp_path / "out2"), "--until", "abstraction"],
            out,
            err,
        )
        == 0
    )
    assert "A012" not in err.getvalue()
    assert not math.isnan(x)
