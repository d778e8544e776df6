"""Small maps far from the origin are meshed in a frame next to the origin.

Triangle's quality refinement computes its new points in absolute coordinates; on a centimetre
room a million metres out they lost the digits that separate the features and Triangle crashed
the process (a segmentation fault, no diagnostic). The mesh is now made in a frame shifted by
an offset whose subtraction is exact, and shifted back.
"""

from __future__ import annotations

import json
import random
import subprocess
import sys
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import shapely
import triangle
from shapely.geometry import Polygon, box

from tlmpc.abstraction.triangulate import exact_shift, triangulate_in_frame

#: A 1 cm room at (1e6, -1e6) with four holes, meshed with min_angle 30 (it crashed Triangle).
FAR_ROOM: dict[str, Any] = {
    "version": 1,
    "workspace": {
        "boundary": {"rect": [1000000.0, -1000000.0, 1000000.01, -999999.99]},
        "holes": [
            {
                "rect": [
                    1000000.003933261,
                    -999999.9954876596,
                    1000000.0050553313,
                    -999999.9938713945,
                ]
            },
            [
                [1000000.0043099012, -999999.9937524549],
                [1000000.0041757824, -999999.9935798926],
                [1000000.0033508042, -999999.9941602965],
                [1000000.0032904154, -999999.9942404226],
            ],
            [
                [1000000.002663296, -999999.9959155335],
                [1000000.0015025401, -999999.996537203],
                [1000000.001414105, -999999.9969676116],
                [1000000.0014309013, -999999.9971307461],
                [1000000.0015029797, -999999.9981766205],
                [1000000.0032813516, -999999.9975363609],
            ],
            [
                [1000000.0053477947, -999999.9915484303],
                [1000000.0047895452, -999999.991620914],
                [1000000.004655889, -999999.9912514179],
                [1000000.0042398938, -999999.9914293541],
                [1000000.0040400026, -999999.9927243154],
                [1000000.0051337536, -999999.9928979441],
                [1000000.0051241086, -999999.9929947556],
            ],
        ],
    },
    "regions": {
        "a": {"rect": [1000000.0003, -999999.9997, 1000000.002, -999999.998]},
        "b": {"rect": [1000000.008, -999999.992, 1000000.0097, -999999.9903]},
        "c": {
            "rect": [1000000.0041450998, -999999.9948042231, 1000000.0058021374, -999999.9944342795]
        },
    },
    "robot": {
        "start": [1000000.0057315758, -999999.9934690087],
        "max_speed": 7.0,
        "radius": 0.00031839140082606045,
        "disturbance": 3.15,
        "model": "unicycle",
        "offset": 2.2436649413882987e-05,
    },
    "task": ["visit b then a"],
    "options": {"margin": 0.00025753632514544117, "min_angle": 30},
}


#: Stop after the mesh, quietly.
QUIET_MESH = ("-q", "--until", "abstraction")


def _free_space(workspace: dict[str, Any]) -> shapely.Geometry:
    def shape(s: dict[str, Any] | list[list[float]]) -> Polygon:
        return box(*s["rect"]) if isinstance(s, dict) else Polygon(s)

    return shape(workspace["boundary"]).difference(
        shapely.union_all([shape(h) for h in workspace["holes"]])
    )


def test_a_centimetre_room_a_million_metres_out_is_meshed(tmp_path: Path) -> None:
    mission = tmp_path / "far.json"
    mission.write_text(json.dumps(FAR_ROOM))
    out = tmp_path / "out"
    # a subprocess: the crash this guards against kills the process that meshes
    run = subprocess.run(
        [sys.executable, "-m", "tlmpc", "compile", str(mission), "-o", str(out), *QUIET_MESH],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    mesh = json.loads((out / "abstraction.json").read_text())
    vertices = np.array(mesh["vertices"])
    corners = vertices[np.array(mesh["triangles"])]
    # the triangles tile the configuration space (the free space eroded by the body), which
    # lies in the free space as written: every triangle inside it, none degenerate
    free = _free_space(FAR_ROOM["workspace"])
    tolerance = 1e-9 * 0.01 + 8 * np.finfo(np.float64).eps * 1e6
    for tri in corners:
        piece = Polygon(tri)
        assert piece.area > 0.0
        assert free.buffer(tolerance).contains(piece)


def test_the_input_vertices_come_back_exactly_and_the_mesh_is_the_shifted_one() -> None:
    rng = random.Random(7)
    for _ in range(25):
        offset = np.array([rng.choice([1e6, -4e6, 5e5, 123.25]), rng.choice([4e6, -1e6, 7.5])])
        size = rng.choice([0.01, 1.0, 30.0])
        ring = [(0.0, 0.0), (size, 0.0), (size, size), (0.0, size)]
        inner = [(size * rng.uniform(0.1, 0.9), size * rng.uniform(0.1, 0.9)) for _ in range(6)]
        local = np.array(ring + inner)
        data = {
            "vertices": local + offset,
            "segments": np.array([[0, 1], [1, 2], [2, 3], [3, 0]]),
        }
        made = triangulate_in_frame(data, "pzQq30a" + repr(size * size / 50))
        assert np.array_equal(made["vertices"][: len(local)], data["vertices"])
        # the same mesh as Triangle makes of the same points at the origin (the shift of the
        # input is exact, so Triangle sees the same geometry as the shifted input)
        shift = np.array([exact_shift(data["vertices"][:, 0]), exact_shift(data["vertices"][:, 1])])
        reference = triangle.triangulate(
            {"vertices": data["vertices"] - shift, "segments": data["segments"]},
            "pzQq30a" + repr(size * size / 50),
        )
        assert np.array_equal(made["triangles"], reference["triangles"])
        assert np.allclose(made["vertices"], reference["vertices"] + shift, rtol=0.0, atol=1e-9)


def test_exact_shift_subtracts_exactly() -> None:
    rng = np.random.default_rng(3)
    spreads = [
        centre + rng.uniform(-1, 1, 50) * abs(centre) * rng.choice([1e-9, 0.1, 0.6, 3.0])
        for centre in (1e6, -4e6, 3.0, -0.5, 0.0)
    ]
    # one side of zero but wider than a factor of two: no offset subtracts exactly from all
    spreads += [np.array([0.1, 3.3, 1e6 + 0.7]), -np.array([0.3, 7.1, 4e6 + 0.1])]
    for values in spreads:
        shift = exact_shift(values)
        # exact: adding the shift back gives every value bit for bit, and the differences
        # equal the exact rational differences
        assert np.array_equal((values - shift) + shift, values)
        assert all(Fraction(v - shift) == Fraction(v) - Fraction(shift) for v in values.tolist())
