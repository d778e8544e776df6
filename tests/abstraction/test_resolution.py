"""Features below the snapping grid are refused (G030, G031), never planned on a mesh that
lacks them; features the grid represents pass, wherever they lie.

The oracle for "the mesh would lose it" is shapely on the written polygons: a strip narrower
than the grid, and a gap narrower than it, checked against the grid of ``grid_size``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import shapely
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.resolution import subgrid_problems
from tlmpc.base.errors import InvalidInputError
from tlmpc.mission import load_mission_text
from tlmpc.mission.grid import grid_size
from tlmpc.mission.model import Mission

BASE = """version: 1
name: grid
workspace:
  boundary: {rect: [0, 0, 10, 10]}
  holes: HOLES
regions:
  goal: {rect: [8, 1, 9, 9]}
REGIONS
robot: {start: [1, 5], max_speed: 1.0}
ltl: "F goal"
"""


def mission(regions: str = "", holes: str = "[]", tmp: Path | None = None) -> Mission:
    text = BASE.replace("REGIONS", regions).replace("HOLES", holes)
    if tmp is None:
        return load_mission_text(text, "m.yaml")
    path = tmp / "m.yaml"
    path.write_text(text)
    return load_mission_text(text, str(path))


def test_a_strip_thinner_than_the_grid_is_refused_at_its_line(tmp_path: Path) -> None:
    m = mission("  wall: [[5, 0], [5.000000003, 0], [5.000000003, 10], [5, 10]]", tmp=tmp_path)
    assert shapely.Polygon(m.regions[1].polygon).minimum_rotated_rectangle.length > 0
    width = 0.000000003
    assert width < grid_size(m)  # the fact that makes the mesh lose it
    with pytest.raises(InvalidInputError) as caught:
        build_abstraction(m)
    (problem,) = caught.value.diagnostics
    assert problem.code == "G030"
    assert "'wall'" in problem.message
    assert problem.line == 8
    assert problem.file == str(tmp_path / "m.yaml")


def test_a_region_losing_only_a_thin_arm_is_refused() -> None:
    arm = 3.000000003
    outline = [[2, 2], [4, 2], [4, 4], [arm, 4], [arm, 9], [3, 9], [3, 4], [2, 4]]
    m = mission("  key: " + yaml.safe_dump(outline, default_flow_style=True).strip())
    raw = shapely.Polygon(outline)
    snapped = shapely.set_precision(raw, grid_size(m))
    assert snapped.area > 0  # the square survives ...
    assert snapped.distance(shapely.Point(3, 9)) > 1  # ... the arm's tip does not
    assert [d.code for d in subgrid_problems(m)] == ["G030"]


def test_a_thin_wall_hole_is_refused() -> None:
    m = mission(holes="[[[5, 0.5], [5.000000004, 0.5], [5.000000004, 9.5], [5, 9.5]]]")
    codes = [d.code for d in subgrid_problems(m)]
    assert codes == ["G030"]


def test_a_gap_below_the_grid_is_refused() -> None:
    m = mission(
        "  a: {rect: [2, 2, 4, 4]}\n  b: [[4.000000002, 2], [6, 2], [6, 4], [4.000000002, 4]]"
    )
    a, b = (shapely.Polygon(r.polygon) for r in m.regions[1:])
    assert not a.intersects(b)
    assert a.distance(b) < grid_size(m)
    codes = [d.code for d in subgrid_problems(m)]
    assert codes == ["G031"]


def test_features_on_or_above_the_grid_pass() -> None:
    third = 1 / 3
    m = mission(
        f"  a: [[2, 2], [{3 + third}, 2], [{3 + third}, {3 + third}], [2, {3 + third}]]\n"
        "  b: [[4.00000002, 2], [6, 2], [6, 4], [4.00000002, 4]]\n"
        "  c: {rect: [6, 6, 6.00001, 7]}"
    )
    assert subgrid_problems(m) == []
    build_abstraction(m)


@settings(deadline=None, max_examples=20)
@given(
    width=st.floats(1e-10, 1e-5),
    x=st.floats(2.0, 7.0),
)
def test_strips_are_refused_exactly_when_thinner_than_the_grid(width: float, x: float) -> None:
    region = [[x, 1.0], [x + width, 1.0], [x + width, 9.0], [x, 9.0]]
    m = mission("  strip: " + yaml.safe_dump(region, default_flow_style=True).strip())
    grid = grid_size(m)
    codes = [d.code for d in subgrid_problems(m)]
    snapped = shapely.set_precision(shapely.Polygon(region), grid)
    if width < grid / 2:
        assert codes == ["G030"]  # far below the grid: it collapses
    elif width > 4 * grid:
        assert codes == []  # the grid represents it, moved by under a step
    if not codes:
        assert snapped.area > 0  # a feature let through survives snapping
