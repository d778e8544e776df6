"""A map beyond the extended sides' budget (a 6 x 6 grid of rooms: 144 sides > MAX_SIDES)
compiles at 0.6 x max_speed on the reflex cuts' mesh, where no triangle and no cell of the
mission's own mesh carries it; every cell step of that plan is then run by the independent
adversarial Euler loop (tests/oracles/cell_adversary.py) from its corners, centroid and random
points, pushed out of the nearest kept side, against xi, or at random: a move leaves only
across its interface, a stay never leaves."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from cell_adversary import CellLoop
from shapely.geometry import Point

import tlmpc
from tlmpc.abstraction.lines import MAX_SIDES

ROOMS = 6


def _grid(disturbance: float) -> dict[str, Any]:
    regions = {
        f"r{i}_{j}": {"rect": [i + 0.25, j + 0.25, i + 0.75, j + 0.75]}
        for i in range(ROOMS)
        for j in range(ROOMS)
    }
    return {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, ROOMS, ROOMS]}},
        "regions": regions,
        "robot": {"start": [1.5, 2.5], "max_speed": 1.0, "disturbance": disturbance},
        "options": {"min_angle": None, "max_area": None},
        "task": ["visit r4_1 and r1_4"],
    }


@pytest.fixture(scope="module")
def compiled() -> Any:
    assert 4 * ROOMS * ROOMS > MAX_SIDES  # the extended sides' mesh is not built
    return tlmpc.compile(_grid(0.6))


def test_the_grid_compiles_on_the_reflex_cells(compiled: Any) -> None:
    steps = compiled.artifacts["controllers.json"]["steps"]
    assert {s.get("kind") for s in steps} == {"cell"}
    assert compiled.artifacts["verdict.json"]["verdict"] == "satisfied"
    # the cells are the faces of the cells' own mesh: the grid's (2 x 6 + 1)^2 rectangles,
    # the two goal rooms each cut further about its core (the goal depth)
    faces = compiled.artifacts["abstraction.json"]["stats"]["cell_faces"]
    assert compiled.artifacts["controllers.json"]["stats"]["cells"] == len(set(faces))
    assert len(set(faces)) > (2 * ROOMS + 1) ** 2


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["kept", "against", "random"])
def test_adversarial_runs_leave_only_through_the_interface(compiled: Any, kind: str) -> None:
    d = 0.6
    for step in compiled.artifacts["controllers.json"]["steps"][:6]:
        loop = CellLoop(step)
        rng = np.random.default_rng(11)
        centre = np.asarray(loop.polygon.centroid.coords[0])
        starts = [centre + 0.999 * (np.asarray(c) - centre) for p in loop.corners for c in p]
        starts.append(centre)
        low, high = np.asarray(loop.polygon.bounds[:2]), np.asarray(loop.polygon.bounds[2:])
        while len(starts) < 12:
            p = rng.uniform(low, high)
            if loop.polygon.contains(Point(p)):
                starts.append(p)
        for k, start in enumerate(starts):
            outcome, gap = loop.run(start.tolist(), d, kind, dt=0.005, horizon=8.0, seed=k)
            if loop.direction is None:
                assert outcome == "held", (step["step"], start, outcome, gap)
            else:
                assert outcome == "exit", (step["step"], start, outcome, gap)
