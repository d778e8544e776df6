"""The convex cells' stay centre search keeps to its budget of moves.

A pattern search along the axes on r / R stalls at a coarse step on a crease of the ratio and
then climbed along it at a fine step, one step at a time: on a 255-triangle mission with a
disturbance (a wall with one door) one cell's search made 2.46 million moves and evaluated
r / R 7.4 million times, and the plan stage ran for minutes of CPU. The budget counts the
search's moves; the work is asserted as counts, never as seconds.

Oracles: shapely for the width at the centre found (the centre's distance to the cell's
boundary over its largest distance to a corner), and a dense grid of the cell for how close
that width comes to the largest r / R.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import shapely

import tlmpc
from tlmpc.planning import cells
from tlmpc.planning.cells import CENTRE_MOVES, CentreSearch, centre_evaluations, stay_centre

#: A cell of the mission below (a triangle of one of the convex cells' meshes its plan stage
#: tries), counter-clockwise, whose search climbed a crease of r / R for 2.46 million moves.
CREASED = [(2.92976467, 4.76148517), (2.93839055, 4.76233474), (2.93411945, 4.8057)]

#: An 8 x 10 room split by a wall with one 0.327-wide door, a body of radius 0.1 and a
#: disturbance of 0.3 x max_speed: no plan on triangles or convex cells rejects it (C032).
DOOR: dict[str, Any] = {
    "version": 1,
    "name": "door",
    "workspace": {
        "boundary": {"rect": [0, 0, 8, 10]},
        "holes": [
            [[4.0185, 0.0], [4.0185, 4.6422], [3.0185, 4.6422], [3.0185, 0.0]],
            [[4.0185, 4.9692], [4.0185, 10.0], [3.0185, 10.0], [3.0185, 4.9692]],
        ],
    },
    "regions": {
        "a": [[1.875, 0.037], [1.875, 1.473], [0.439, 1.473], [0.439, 0.037]],
        "b": [[7.432, 8.298], [7.432, 8.928], [6.802, 8.928], [6.802, 8.298]],
    },
    "robot": {"start": [7.51, 3.81], "max_speed": 1.0, "radius": 0.1, "disturbance": 0.3},
    "task": ["patrol a, b"],
    "options": {"margin": 0},
}


def _largest_on_grid(polygon: list[tuple[float, float]], size: int = 1200) -> float:
    """The largest r / R over a size x size grid of the polygon's bounding box."""
    corners = np.array(polygon)
    low, high = corners.min(axis=0), corners.max(axis=0)
    x, y = np.meshgrid(np.linspace(low[0], high[0], size), np.linspace(low[1], high[1], size))
    inside = np.full(x.shape, np.inf)
    for (ax, ay), (bx, by) in zip(polygon, [*polygon[1:], polygon[0]], strict=True):
        length = math.hypot(bx - ax, by - ay)
        inside = np.minimum(inside, ((ay - by) * (x - ax) + (bx - ax) * (y - ay)) / length)
    reach = np.max([np.hypot(x - px, y - py) for px, py in polygon], axis=0)
    return float((inside / reach).max())


def test_a_creased_cells_search_keeps_to_its_budget() -> None:
    found = stay_centre(CREASED)
    assert found.moves <= CENTRE_MOVES
    assert found.evaluations <= centre_evaluations()
    # the centre is inside and its width is r / R there
    cell = shapely.Polygon(CREASED)
    centre = shapely.Point(found.centre)
    assert cell.contains(centre)
    reach = max(math.dist(found.centre, corner) for corner in CREASED)
    assert found.width == pytest.approx(cell.exterior.distance(centre) / reach, rel=1e-9)
    # the climb the budget cuts short gained in the last digits only
    assert found.width >= _largest_on_grid(CREASED) - 1e-9


def test_a_small_mission_with_a_disturbance_is_refused_within_the_budget(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Every centre search of the plan stage's convex cells keeps to the budget, some on this
    mission spend it, and the mission is refused at once with the located C032."""
    searches: list[CentreSearch] = []

    def counted(polygon: list[tuple[float, float]]) -> CentreSearch:
        found = stay_centre(polygon)
        assert found.evaluations <= centre_evaluations(), (polygon, found)
        searches.append(found)
        return found

    monkeypatch.setattr(cells, "stay_centre", counted)
    with pytest.raises(tlmpc.InvalidInputError) as refused:
        tlmpc.compile(DOOR)
    assert {d.code for d in refused.value.diagnostics} == {"C032"}
    assert all(d.path == "$.robot.disturbance" for d in refused.value.diagnostics)
    assert any(found.moves == CENTRE_MOVES for found in searches)
    assert sum(found.evaluations for found in searches) <= len(searches) * centre_evaluations()
