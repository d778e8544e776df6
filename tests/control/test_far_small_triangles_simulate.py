"""The exact simulation of small triangles far from the origin.

An exit step counted its start as "already on the exit edge" within 1e-12 of the largest
coordinate: at 4e6 that is 4e-6, a fifth of a triangle 2e-5 high, so a step was declared
crossed where it started and the next one began outside its triangle (C031, exit 3). The
tolerance is now the coordinates' rounding. The trace is checked here against scipy's matrix
exponential of each step's field and against the triangles themselves.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.linalg import expm
from shapely.geometry import LineString, Point, Polygon

from tlmpc.cli import main

EPS = float(np.finfo(np.float64).eps)


def _room(scale: float, offset: float, radius: float) -> dict[str, Any]:
    """A square room 10 * scale wide at (offset, offset), a pillar, two goals to patrol."""

    def at(x: float, y: float) -> list[float]:
        return [offset + x * scale, offset + y * scale]

    return {
        "version": 1,
        "workspace": {
            "boundary": {"rect": [offset, offset, offset + 10 * scale, offset + 10 * scale]},
            "holes": [[at(4, 4), at(6, 4), at(6, 6), at(4, 6)]],
        },
        "regions": {
            "a": [at(0.5, 0.5), at(2, 0.5), at(2, 2), at(0.5, 2)],
            "b": [at(8, 8), at(9.5, 8), at(9.5, 9.5), at(8, 9.5)],
        },
        "robot": {"start": at(1, 1), "max_speed": 1.0, "radius": radius * scale},
        "task": ["patrol a and b"],
    }


@pytest.mark.parametrize(
    ("scale", "offset", "radius"),
    [(3e-4, 4e6, 0.1), (1e-5, 4e6, 0.0), (3e-4, 1e7, 0.1)],
)
def test_small_triangles_far_out_simulate_exactly(
    tmp_path: Path, scale: float, offset: float, radius: float
) -> None:
    mission = tmp_path / "room.json"
    mission.write_text(json.dumps(_room(scale, offset, radius)))
    out = tmp_path / "out"
    err = io.StringIO()
    code = main(["compile", str(mission), "-o", str(out), "-q"], io.StringIO(), err)
    assert code == 0, err.getvalue()
    controllers = json.loads((out / "controllers.json").read_text())
    trace = json.loads((out / "trace.json").read_text())
    points = np.array(trace["points"])
    runs: list[tuple[int, list[int]]] = []
    for index, step in enumerate(trace["steps"]):
        if runs and runs[-1][0] == step and runs[-1][1][-1] == index - 1:
            runs[-1][1].append(index)
        else:
            runs.append((step, [index]))
    for step, indices in runs:
        field = controllers["steps"][step]
        corners = np.array(field["vertices"])
        size = float(np.ptp(corners, axis=0).max())
        rounding = 8 * EPS * float(np.abs(corners).max())
        triangle = Polygon(corners)
        # every sample of the step in its triangle, to the coordinates' rounding
        for index in indices:
            assert triangle.distance(Point(points[index, 1:])) <= rounding + 1e-9 * size
        if field["stay"]:
            continue
        # the step ends on its exit edge
        edge = field["exit_edge"]
        ends = LineString([corners[(edge + 1) % 3], corners[(edge + 2) % 3]])
        assert ends.distance(Point(points[indices[-1], 1:])) <= rounding + 1e-9 * size
        # the samples follow the field: scipy's exponential of the step's affine flow, in the
        # frame of its first corner (y = x - v0, y' = K y + w0)
        matrix = np.zeros((3, 3))
        matrix[:2, :2] = field["K"]
        matrix[:2, 2] = field["vertex_velocities"][0]
        first = indices[0]
        start = np.array([*(points[first, 1:] - corners[0]), 1.0])
        for index in indices[1:]:
            flowed = expm(matrix * (points[index, 0] - points[first, 0])) @ start
            assert np.linalg.norm(flowed[:2] + corners[0] - points[index, 1:]) <= (
                1e-6 * size + 64 * rounding
            )
