"""Convex cells reject disturbances no triangle can (tlmpc.planning.cells, tlmpc.control.cells).

* A two-room mission compiles at 0.6 and at 0.707 x max_speed (a square cell pushes
  max_speed / sqrt(2) at a right corner) and is refused just above 1 / sqrt(2) with C032
  stating the bound on cells; on triangles alone it is refused from sin(45 / 2) (0.383).
* Every cell step is run by an independent adversarial Euler loop (tests/oracles/
  cell_adversary.py) from its corners, its centroid and random points, pushed out of the
  nearest kept side, against xi, or at random: a move leaves only across its interface, a stay
  never leaves.
* Every row is checked on a dense sample with shapely geometry, and each cell move's stated
  width equals an independent per-vertex LP (cvxpy) at the same xi: feasible just below,
  infeasible just above.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
import pytest
from cell_adversary import CellLoop
from shapely.geometry import Point

import tlmpc
from tlmpc.base.errors import TlmpcError


def _rooms(disturbance: float) -> dict[str, Any]:
    return {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, 6, 3]}},
        "regions": {"a": {"rect": [3, 0, 6, 3]}},
        "robot": {"start": [1.5, 1.5], "max_speed": 1.0, "disturbance": disturbance},
        "options": {"min_angle": None, "goal_depth": 0, "margin": 0},
        "ltl": "F G a",
    }


@pytest.fixture(scope="module")
def rooms() -> Any:
    return tlmpc.compile(_rooms(0.6))


def test_rooms_compile_on_cells_and_verify(rooms: Any) -> None:
    steps = rooms.artifacts["controllers.json"]["steps"]
    assert [s.get("kind") for s in steps] == ["cell", "cell"]
    assert rooms.artifacts["verdict.json"]["verdict"] == "satisfied"


@pytest.mark.parametrize("disturbance", [0.7071])
def test_just_below_the_square_bound_compiles(disturbance: float) -> None:
    compiled = tlmpc.compile(_rooms(disturbance))
    assert compiled.artifacts["verdict.json"]["verdict"] == "satisfied"


def test_just_above_the_square_bound_is_refused_with_the_cell_bound() -> None:
    with pytest.raises(TlmpcError) as caught:
        tlmpc.compile(_rooms(0.7072))
    diagnostics = caught.value.diagnostics
    assert {d.code for d in diagnostics} == {"C032"}
    hint = diagnostics[0].hint or ""
    assert f"plans reject at most {math.sqrt(0.5):.6g}" in hint


def test_example1_beyond_every_cell_states_the_cells_bound() -> None:
    """At 0.7 Example 1 is refused; the hint states both bounds: triangles sin 22.5 degrees
    and, larger, what its cells (on the mesh of its extended sides) carry at most; just below
    that value a plan on cells exists where the widest lasso found it (below 0.646 it compiles
    at 0.6)."""
    from pathlib import Path

    import yaml

    doc = yaml.safe_load(
        (Path(__file__).resolve().parents[2] / "specs" / "example1.yaml").read_text()
    )
    doc["robot"]["disturbance"] = 0.7
    with pytest.raises(TlmpcError) as caught:
        tlmpc.compile(doc, until="control")
    hint = caught.value.diagnostics[0].hint or ""
    assert "any plan on this mesh rejects is 0.382683" in hint
    stated = float(hint.split("plans reject at most ")[1].split(" ")[0])
    assert math.sin(math.radians(22.5)) < stated < 0.7
    doc["robot"]["disturbance"] = 0.6
    compiled = tlmpc.compile(doc, until="control")
    assert {s.get("kind") for s in compiled.artifacts["controllers.json"]["steps"]} == {"cell"}


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["kept", "against", "random"])
def test_adversarial_runs_leave_only_through_the_interface(rooms: Any, kind: str) -> None:
    d = 0.6
    for step in rooms.artifacts["controllers.json"]["steps"]:
        loop = CellLoop(step)
        rng = np.random.default_rng(7)
        starts = [np.asarray(c, dtype=float) for piece in loop.corners for c in piece]
        centre = np.asarray(loop.polygon.centroid.coords[0])
        starts = [centre + 0.999 * (s - centre) for s in starts] + [centre]
        low, high = np.asarray(loop.polygon.bounds[:2]), np.asarray(loop.polygon.bounds[2:])
        while len(starts) < 30:
            p = rng.uniform(low, high)
            if loop.polygon.contains(Point(p)):
                starts.append(p)
        for k, start in enumerate(starts):
            outcome, gap = loop.run(start.tolist(), d, kind, dt=0.01, horizon=40.0, seed=k)
            if loop.direction is None:
                assert outcome == "held", (step["step"], start, outcome, gap)
            else:
                assert outcome == "exit", (step["step"], start, outcome, gap)


def test_rows_hold_on_a_dense_sample(rooms: Any) -> None:
    d = 0.6
    for step in rooms.artifacts["controllers.json"]["steps"]:
        loop = CellLoop(step)
        rng = np.random.default_rng(3)
        low, high = np.asarray(loop.polygon.bounds[:2]), np.asarray(loop.polygon.bounds[2:])
        for _ in range(400):
            p = rng.uniform(low, high)
            if not loop.polygon.contains(Point(p)):
                continue
            u = loop.field(p)
            assert np.linalg.norm(u) <= 1.0 + 1e-9
            if loop.direction is not None:
                assert loop.direction @ u > d
        for side in loop.kept:
            (ax, ay), (bx, by) = side.coords
            inward = np.array([ay - by, bx - ax]) / math.hypot(bx - ax, by - ay)
            for s in np.linspace(0.0, 1.0, 21):
                u = loop.field(np.array([ax + s * (bx - ax), ay + s * (by - ay)]))
                assert inward @ u > d


def _lp_width(
    normals_per_vertex: list[list[tuple[float, float]]], xi: tuple[float, float]
) -> float:
    """max d with m·u_v >= d for each vertex's rows and |u_v| <= 1: independent, by cvxpy."""
    import cvxpy as cp

    d = cp.Variable()
    constraints = []
    for normals in normals_per_vertex:
        u = cp.Variable(2)
        constraints.append(cp.norm(u) <= 1.0)
        for a in [*normals, xi]:
            constraints.append(np.asarray(a) @ u >= d)
    cp.Problem(cp.Maximize(d), constraints).solve()
    return float(d.value)


def test_stated_widths_equal_an_independent_program() -> None:
    from pathlib import Path

    from tlmpc.mission.body import requested_margin
    from tlmpc.mission.load import load_mission
    from tlmpc.planning.cells import partition
    from tlmpc.planning.mission import abstraction_for

    mission = load_mission(Path(__file__).resolve().parents[2] / "specs" / "example1.yaml")
    cells = partition(abstraction_for(mission, requested_margin(mission)))
    checked = 0
    for cell in cells.cells[:8]:
        for target in sorted({s.neighbour for s in cell.sides if s.neighbour >= 0}):
            move = cells.move(cell.index, target)
            if move.width <= 0.0:
                continue
            rows = [list(n) for n in cells.vertex_normals(move).values()]
            assert _lp_width(rows, move.xi) == pytest.approx(move.width, abs=1e-6)
            checked += 1
    assert checked >= 10


def _first_move(compiled: Any) -> Any:
    from tlmpc.control.io import controllers_from_json

    controllers = controllers_from_json(compiled.artifacts["controllers.json"])
    return next(c for c in controllers.steps if c.cell is not None and not c.is_stay)


def test_the_recheck_counts_the_disturbance(rooms: Any) -> None:
    """The re-check holds every row to the disturbance: the move's field (width 0.7071)
    passes at 0.6 and fails at 0.71, where its kept corners push less than d."""
    from tlmpc.control.cells import violated

    move = _first_move(rooms)
    assert violated(move, 1.0, 0.6) is None
    assert violated(move, 1.0, 0.71) is not None
    slow = replace(
        move,
        cell=replace(move.cell, velocities=move.cell.velocities * 0.5),
    )
    assert violated(slow, 1.0, 0.4) is not None  # 0.5 x 0.7071 < 0.4 along xi and inward
    # nine tenths of full speed along xi, a tenth as solved: the flow rows hold (> 0.9),
    # a kept corner's row only just (0.07 > 0, < 0.6)
    along = np.broadcast_to(np.asarray(move.cell.direction), move.cell.velocities.shape)
    velocities = 0.9 * along + 0.1 * move.cell.velocities
    flowing = replace(move, cell=replace(move.cell, velocities=velocities))
    problem = violated(flowing, 1.0, 0.6)
    assert problem is not None
    assert "kept side" in problem
    # the kept rows as solved, the flow direction turned 40 degrees: the corner velocities
    # (45 degrees either side of xi) move along it by cos 5 and cos 85 degrees, 0.087 < 0.6
    (x, y), turn = move.cell.direction, math.radians(40.0)
    direction = (x * math.cos(turn) - y * math.sin(turn), x * math.sin(turn) + y * math.cos(turn))
    tilted = replace(move, cell=replace(move.cell, direction=direction))
    problem = violated(tilted, 1.0, 0.6)
    assert problem is not None
    assert "along xi" in problem


def test_the_simulation_refuses_a_field_that_leaves_by_a_kept_side(rooms: Any) -> None:
    """A move's field turned round (every velocity negated, the interface now behind it)
    leaves across a kept side: the exact simulation reports C031 instead of ending the step."""
    from tlmpc.base.errors import SolverError
    from tlmpc.simulate.cells import cell_step

    move = _first_move(rooms)
    field = move.cell
    assert field.direction is not None
    turned = replace(
        move,
        exit_speed=move.exit_speed,
        cell=replace(
            field,
            velocities=-field.velocities,
            gains=-field.gains,
            offsets=-field.offsets,
            direction=(-field.direction[0], -field.direction[1]),
        ),
    )
    with pytest.raises(SolverError) as caught:
        cell_step(turned, np.array([1.5, 1.5]), 1.0)
    assert caught.value.diagnostics[0].code == "C031"
