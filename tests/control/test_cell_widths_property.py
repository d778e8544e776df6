"""The width a cell move states is the largest disturbance its rows admit, on random convex
workspaces with a random rectangle region (so several cells): an independent second-order
cone program (cvxpy) over the same rows, re-derived here from the cell's polygon, reaches the
stated width at the stated xi, and no direction of a 24-direction fan does better than the
stated width by more than the fan's resolution allows."""

from __future__ import annotations

import math

import cvxpy as cp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import MultiPoint

from tlmpc.mission.load import load_mission_text
from tlmpc.planning.cells import partition
from tlmpc.planning.mission import abstraction_for


def _rows(polygon: list[tuple[float, float]], kept: list[int]) -> dict[int, list[np.ndarray]]:
    """Per boundary vertex, the inward unit normals of the kept sides through it (sides k:
    polygon[k] -> polygon[k + 1], counter-clockwise)."""
    rows: dict[int, list[np.ndarray]] = {k: [] for k in range(len(polygon))}
    for k in kept:
        (ax, ay), (bx, by) = polygon[k], polygon[(k + 1) % len(polygon)]
        normal = np.array([ay - by, bx - ax])  # left of a -> b: inside
        normal = normal / np.linalg.norm(normal)
        rows[k].append(normal)
        rows[(k + 1) % len(polygon)].append(normal)
    return rows


def _best(rows: dict[int, list[np.ndarray]], xi: np.ndarray) -> float:
    d = cp.Variable()
    constraints = []
    for normals in rows.values():
        u = cp.Variable(2)
        constraints.append(cp.norm(u) <= 1.0)
        constraints += [a @ u >= d for a in [*normals, xi]]
    cp.Problem(cp.Maximize(d), constraints).solve()
    return float(d.value)


@pytest.mark.slow
@settings(max_examples=8, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, 40), st.integers(0, 40)), min_size=5, max_size=9, unique=True
    ),
    st.floats(0.2, 0.8),
    st.floats(0.2, 0.8),
)
def test_stated_widths_are_the_rows_optimum(
    corners: list[tuple[int, int]], fx: float, fy: float
) -> None:
    hull = MultiPoint([(float(x), float(y)) for x, y in corners]).convex_hull
    if hull.geom_type != "Polygon" or hull.area < 100.0:
        return
    ring = [(round(x, 6), round(y, 6)) for x, y in list(hull.exterior.coords)[:-1]]
    minx, miny, maxx, maxy = hull.bounds
    cx, cy = minx + fx * (maxx - minx), miny + fy * (maxy - miny)
    if not hull.buffer(-2.0).contains(MultiPoint([(cx, cy)]).centroid):
        return
    text = (
        "version: 1\nworkspace:\n  boundary: "
        + str([list(p) for p in ring])
        + f"\nregions:\n  a: {{rect: [{cx - 1:.6f}, {cy - 1:.6f}, {cx + 1:.6f}, {cy + 1:.6f}]}}\n"
        + f"robot: {{start: [{cx:.6f}, {cy:.6f}], max_speed: 1.0}}\n"
        + 'options: {min_angle: null, goal_depth: 0}\nltl: "F a"\n'
    )
    mission = load_mission_text(text, "<random>")
    cells = partition(abstraction_for(mission, 0.0))
    points = cells.abstraction.vertices
    for cell in cells.cells:
        polygon = [tuple(points[v].tolist()) for v in cell.boundary]
        for target in sorted({s.neighbour for s in cell.sides if s.neighbour >= 0}):
            move = cells.move(cell.index, target)
            if not move.kept:
                continue
            rows = _rows(polygon, list(move.kept))
            assert _best(rows, np.asarray(move.xi)) == pytest.approx(move.width, abs=1e-5)
            fan = max(
                _best(rows, np.array([math.cos(t), math.sin(t)]))
                for t in np.linspace(0.0, 2.0 * math.pi, 24, endpoint=False)
            )
            assert fan <= move.width + 1e-5
