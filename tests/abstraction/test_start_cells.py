"""The triangles holding a start point, against shapely's closed-polygon test."""

from __future__ import annotations

from functools import cache
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st
from starts import start_triangles

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.model import Abstraction
from tlmpc.abstraction.starts import start_cells
from tlmpc.mission import load_mission

ROOT = Path(__file__).resolve().parents[2]


@cache
def _abstraction() -> Abstraction:
    return build_abstraction(load_mission(ROOT / "specs" / "example1.yaml"))


@st.composite
def _points(draw: st.DrawFn) -> tuple[float, float]:
    """A mesh vertex, a point on an edge, or any point of the mesh's bounding box."""
    abstraction = _abstraction()
    vertices = abstraction.vertices
    kind = draw(st.sampled_from(["vertex", "edge", "anywhere"]))
    if kind == "vertex":
        x, y = vertices[draw(st.integers(0, len(vertices) - 1))]
    elif kind == "edge":
        triangle = abstraction.triangles[draw(st.integers(0, abstraction.num_triangles - 1))]
        a, b = vertices[triangle[0]], vertices[triangle[1]]
        x, y = (a + b) / 2.0
    else:
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        x = draw(st.floats(float(low[0]) - 1.0, float(high[0]) + 1.0))
        y = draw(st.floats(float(low[1]) - 1.0, float(high[1]) + 1.0))
    return float(x), float(y)


@settings(max_examples=60, deadline=None)
@given(_points())
def test_start_cells_are_the_triangles_whose_closed_polygon_holds_the_point(
    point: tuple[float, float],
) -> None:
    abstraction = _abstraction()
    cells = start_cells(abstraction, point)
    expected = start_triangles(abstraction, point)
    assert {cell.triangle for cell in cells} == set(expected)
    for cell in cells:  # an edge through the point is always blocked
        assert expected[cell.triangle] <= set(cell.blocked)
