"""A region's corner on another region's slanted side: in floats it lies a rounding error
beside the side, and the mesh must still node the side there (Triangle ran out of precision,
or crashed the process, on a vertex a hair from a segment)."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st
from test_refine import _check_mesh

from tlmpc.abstraction import build_abstraction
from tlmpc.mission import load_mission_text

# hundredths: a side's midpoint is then a decimal that floats hold only approximately
HUNDREDTHS = st.integers(1, 400).map(lambda k: k / 100)


@settings(deadline=None, max_examples=40)
@given(HUNDREDTHS, HUNDREDTHS, HUNDREDTHS, HUNDREDTHS, HUNDREDTHS, HUNDREDTHS, st.booleans())
def test_a_corner_on_a_slanted_side_is_meshed_with_exact_labels(
    x0: float, y0: float, w: float, h: float, width: float, height: float, depth: bool
) -> None:
    # r0: a right triangle whose slanted side runs from (x0 + w, y0) to (x0, y0 + h); r1: a
    # rectangle whose lower left corner is that side's midpoint, on the far side of it
    cx, cy = x0 + w / 2, y0 + h / 2
    text = f"""\
version: 1
workspace: {{boundary: {{rect: [0, 0, 12, 12]}}}}
regions:
  r0: [[{x0}, {y0}], [{x0 + w}, {y0}], [{x0}, {y0 + h}]]
  r1: {{rect: [{cx}, {cy}, {cx + width}, {cy + height}]}}
robot: {{start: [11.5, 0.5]}}
task: [visit r1]
options: {{goal_depth: {0.05 if depth else 0}}}
"""
    mission = load_mission_text(text, "corner.yaml")
    abstraction = build_abstraction(mission)
    _check_mesh(abstraction, mission)


def test_the_shrunk_case_that_crashed_the_process() -> None:
    text = """\
version: 1
workspace: {boundary: {rect: [0, 0, 7, 16]}}
regions:
  r0: [[2.05, 8.66], [2.85, 8.66], [2.05, 9.86]]
  r1: {rect: [2.45, 9.26, 5.15, 10.76]}
robot: {start: [4.0, 10.91]}
task: [visit r1]
options: {goal_depth: 0}
"""
    mission = load_mission_text(text, "corner.yaml")
    _check_mesh(build_abstraction(mission), mission)
