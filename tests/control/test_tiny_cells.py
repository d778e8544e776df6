"""Cell fields of pieces about 1e-8 in size far from the origin: Example 1 at half max_speed of
disturbance (planned on convex cells), its map shrunk to 1e-6 .. 1e-8 and moved out to 4.5
or 100, where a coordinate's last bit is 1e-7 of a cell's size.

The simulator hands the robot from piece to piece and from cell to cell across facets whose
crossing points it can only place to the rounding of their coordinates; the output simulates
(no C031 "not in the step's cell", no C010) and its trace is checked against scipy's matrix
exponential of each piece's law.  ``tlmpc stage simulate`` reads the controllers back and
re-checks each cell's exit-time bound from its width along xi, a difference of coordinates
that carries that rounding: the untouched file passes, and a bound cut by 1e-4 of itself,
below what the field guarantees in exact rational arithmetic, is refused (U042).
"""

from __future__ import annotations

import io
import json
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
from scipy.linalg import expm
from trace_check import check_speed

import tlmpc
from tlmpc.cli import main
from tlmpc.control.model import EXIT, KEPT, CellField, StepController
from tlmpc.simulate.cells import cell_step

EXAMPLE_1: dict[str, Any] = {
    "version": 1,
    "workspace": {"boundary": [[0, 0], [10, 0], [10, 10], [0, 10]]},
    "regions": {
        "p1": [[0.5, 0.5], [3.0, 0.5], [3.0, 3.0], [0.5, 3.0]],
        "p2": [[1.0, 6.5], [4.0, 6.0], [3.5, 9.0], [1.0, 9.0]],
        "p3": [[6.5, 6.5], [9.5, 6.5], [9.5, 9.5], [6.5, 9.5]],
        "p4": [[7.0, 1.0], [9.5, 1.5], [9.0, 4.0], [6.5, 3.5]],
    },
    "robot": {"start": [1.5, 1.5], "max_speed": 1.0, "disturbance": 0.5},
    "task": ["visit p2 then p3 then p4 then return to p1 while avoiding p2 and p3"],
}


def _shrunk(size: float, offset: tuple[float, float]) -> dict[str, Any]:
    def move(point: list[float]) -> list[float]:
        return [offset[0] + size * point[0] / 10, offset[1] + size * point[1] / 10]

    mission: dict[str, Any] = json.loads(json.dumps(EXAMPLE_1))
    mission["workspace"]["boundary"] = [move(p) for p in EXAMPLE_1["workspace"]["boundary"]]
    mission["regions"] = {k: [move(p) for p in v] for k, v in EXAMPLE_1["regions"].items()}
    mission["robot"]["start"] = move(EXAMPLE_1["robot"]["start"])
    return mission


def _check_cell_flow(trace: dict[str, Any], steps: list[dict[str, Any]], size: float) -> None:
    """Every sample of a cell step lies in its cell and on the exact flow (scipy) of the law
    of the piece the previous sample is in, from that sample."""
    points = np.asarray(trace["points"])
    # a point is placed to the last bits of its coordinates: 1e-7 of a cell of 1e-8 at 4.5
    ulps = 8 * float(np.finfo(np.float64).eps) * float(np.abs(points[:, 1:]).max())
    for k in range(1, len(points)):
        cell = steps[trace["steps"][k]]["cell"]
        pieces = [shapely.Polygon(corners) for corners in cell["vertices"]]
        where = shapely.Point(points[k][1:])
        assert min(piece.distance(where) for piece in pieces) <= 1e-9 * size + ulps, k
        piece = cell["triangles"].index(trace["triangles"][k - 1])
        gain, offset = np.asarray(cell["K"][piece]), np.asarray(cell["g"][piece])
        centre = np.asarray(cell["vertices"][piece]).mean(axis=0)
        field = np.zeros((3, 3))
        field[:2, :2], field[:2, 2] = gain, gain @ centre + offset
        t0, first = points[k - 1][0], points[k - 1][1:]
        expected = (expm((points[k][0] - t0) * field) @ [*(first - centre), 1.0])[:2] + centre
        assert np.linalg.norm(expected - points[k][1:]) <= 1e-6 * size + ulps, k


@pytest.mark.parametrize(
    ("size", "offset"), [(1e-6, (4.5, 1.2)), (1e-7, (100.0, 100.0)), (1e-8, (4.5, 1.2))]
)
def test_tiny_cells_far_out_simulate_on_their_exact_flow(
    size: float, offset: tuple[float, float]
) -> None:
    result = tlmpc.compile(_shrunk(size, offset))
    steps = result.artifacts["controllers.json"]["steps"]
    assert steps
    assert all(s.get("kind") == "cell" for s in steps)
    assert result.artifacts["verdict.json"]["verdict"] == "satisfied"
    trace = result.artifacts["trace.json"]
    check_speed(trace, 1.0, size)
    _check_cell_flow(trace, steps, size)


def _run(*argv: str) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), err.getvalue()


def _exact_least_time(step: dict[str, Any], disturbance: float) -> Fraction:
    """The time the cell's field takes at least to cross it along xi, in rationals."""
    cell = step["cell"]
    xi = [Fraction(c) for c in cell["direction"]]
    along = [xi[0] * Fraction(x) + xi[1] * Fraction(y) for c in cell["vertices"] for x, y in c]
    speed = min(
        xi[0] * Fraction(u) + xi[1] * Fraction(v) for w in cell["vertex_velocities"] for u, v in w
    )
    return (max(along) - min(along)) / (speed - Fraction(disturbance))


def test_tiny_cells_read_back_pass_and_a_cut_exit_time_bound_is_refused(tmp_path: Path) -> None:
    mission = tmp_path / "tiny.json"
    mission.write_text(json.dumps(_shrunk(1e-7, (100.0, 100.0))))
    out = tmp_path / "out"
    code, err = _run("compile", str(mission), "-o", str(out), "-q")
    assert code == 0, err
    path = out / "controllers.json"
    document = json.loads(path.read_text())
    # the premise: a bound the writer computed vector by vector is below the width a matrix
    # product gives over the same speed (last bits of coordinates near 100)
    shorter = []
    for step in document["steps"]:
        cell = step["cell"]
        if cell["direction"] is None:
            continue
        xi = np.asarray(cell["direction"])
        along = np.asarray(cell["vertices"]).reshape(-1, 2) @ xi
        speed = float((np.asarray(cell["vertex_velocities"]).reshape(-1, 2) @ xi).min())
        least = float(along.max() - along.min()) / (speed + 1e-9 - 0.5)
        if step["exit_time_bound"] < least * (1 - 1e-9):
            shorter.append(step["step"])
    assert shorter
    code, err = _run("stage", "simulate", str(out))
    assert code == 0, err

    step = document["steps"][shorter[0]]
    step["exit_time_bound"] *= 1 - 1e-4
    assert step["exit_time_bound"] < _exact_least_time(step, 0.5)
    path.write_text(json.dumps(document))
    code, err = _run("stage", "simulate", str(out))
    assert code == 2, err
    assert err.startswith(f"{path}: error[U042]: controllers.json"), err
    assert f"step {shorter[0]} " in err, err
    assert "exit_time_bound" in err, err


#: Two rooms joined by a door 0.021 wide in a wall 0.002 thick at x = 4.5; a body of 1e-9
#: pushed by 0.278 x max_speed: its cells beside the wall's corners have needle pieces 1e-8
#: thin and 3.7 long.
DOOR: dict[str, Any] = {
    "version": 1,
    "workspace": {
        "boundary": [
            [0, 0], [4.5, 0], [4.5, 1.1643], [4.502, 1.1643], [4.502, 0], [10, 0], [10, 6],
            [4.502, 6], [4.502, 1.1853], [4.5, 1.1853], [4.5, 6], [0, 6],
        ]
    },
    "regions": {
        "g": [[8.0, 3.8], [9.5, 3.8], [9.5, 5.3], [8.0, 5.3]],
        "h": [[0.4, 4.2], [1.4, 4.2], [1.4, 5.5], [0.4, 5.5]],
    },
    "robot": {"start": [1.0, 1.0], "max_speed": 3.0, "radius": 1e-9, "disturbance": 0.834},
    "task": ["visit g then h"],
}  # fmt: skip


def test_a_needle_piece_is_left_within_its_flows_bound() -> None:
    # A state counts as beyond a facet past SLACK of the piece's extent across that facet:
    # past SLACK of its longest height, the run through a needle 1e-8 thin outlasted the
    # bound of its flow (C010).
    result = tlmpc.compile(DOOR)
    steps = result.artifacts["controllers.json"]["steps"]
    assert any(
        min(shapely.Polygon(c).area / shapely.Polygon(c).length for c in s["cell"]["vertices"])
        < 1e-8
        for s in steps
    )
    assert result.artifacts["verdict.json"]["verdict"] == "satisfied"
    trace = result.artifacts["trace.json"]
    check_speed(trace, 3.0, 10.0)
    _check_cell_flow(trace, steps, 10.0)


def _grazing_square(corner: tuple[float, float], size: float, tilt: float) -> StepController:
    """A square cell split by its diagonal, far from the origin, under a uniform field at
    ``tilt`` below the diagonal: it crosses the diagonal at a grazing angle and leaves by the
    right or top side (both exits; left and bottom are kept, pushed inward)."""
    x0, y0 = corner
    a, b, c, d = (x0, y0), (x0 + size, y0), (x0 + size, y0 + size), (x0, y0 + size)
    u = np.array([1.0, 1.0 - tilt]) / np.hypot(1.0, 1.0 - tilt)
    field = CellField(
        triangles=(0, 1),
        vertices=np.array([[a, c, d], [a, b, c]]),
        velocities=np.array([[u] * 3] * 2),
        gains=np.zeros((2, 2, 2)),
        offsets=np.array([u, u]),
        neighbours=((EXIT, KEPT, 1), (EXIT, 0, KEPT)),
        direction=(1.0, 0.0),
        cell=0,
        target_cell=1,
        plan_index=0,
    )
    return StepController(
        step=0, triangle=0, exit_edge=None, next_triangle=1, vertices=field.vertices[0],
        velocities=field.velocities[0], gain=field.gains[0], offset=field.offsets[0],
        exit_speed=float(u[0]), exit_time_bound=size / float(u[0] - 0.0), target=None,
        kind="cell", cell=field,
    )  # fmt: skip


@pytest.mark.parametrize(
    ("corner", "size", "tilt"),
    [
        ((33.64343993341012, 79.05444163941203), 4.040077150299997e-09, 2.29347319377015e-05),
        ((84.14827058210948, 51.44009227062943), 1.051423716382634e-08, 1.815894541260321e-04),
        ((83.72135243352714, 28.90590490908967), 2.694240339533708e-09, 8.279309926218439e-05),
    ],
)
def test_a_grazing_hand_over_is_not_handed_back(
    corner: tuple[float, float], size: float, tilt: float
) -> None:
    # Just past the diagonal the state is still within rounding of it: counted as beyond it
    # in the next piece, it was handed back and forth until MAX_PIECES (C010).
    controller = _grazing_square(corner, size, tilt)
    start = np.array([corner[0] + 0.1 * size, corner[1] + 0.1 * size + 0.3 * tilt * size])
    _, points, _, crossings = cell_step(controller, start, 1.0)
    assert sum(crossings) <= 3
    # oracle: the uniform flow leaves the square on its right side, tilt x size below the top
    # (to the rounding of the coordinates at each of at most three hand-overs)
    end = points[-1]
    ulps = 3 * 8 * float(np.finfo(np.float64).eps) * max(corner)
    assert end[0] == pytest.approx(corner[0] + size, abs=1e-6 * size + ulps)
    assert end[1] == pytest.approx(start[1] + (end[0] - start[0]) * (1 - tilt), abs=ulps)
