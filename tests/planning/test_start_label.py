"""The start point's closed label: every region whose closure holds the start.

The oracle is the rule itself, region by region with shapely (no bounding-box filter): a
region counts when the start lies within 1e-12 of the largest coordinate magnitude from it.
Starts are drawn on region corners, on edges, inside, and just outside.
"""

from __future__ import annotations

import numpy as np
import shapely
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.abstraction import build_abstraction
from tlmpc.mission import load_mission_text
from tlmpc.planning.boundary import start_point_label

MAP = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 8]}
regions:
  a: {rect: [1, 1, 4, 3]}
  b: {rect: [4, 1, 6, 3]}
  c: [[2, 3], [6, 3], [4, 7]]
  d: {rect: [7.5, 0.5, 9, 7.5]}
robot: {start: [0.5, 0.5]}
task: ["visit a"]
options: {min_angle: null, max_area: null}
"""

ABSTRACTION = build_abstraction(load_mission_text(MAP, "m.yaml"))
CORNERS = sorted({tuple(map(float, p)) for poly in ABSTRACTION.regions.values() for p in poly})


def _rule(point: tuple[float, float]) -> tuple[str, ...]:
    extent = max(float(np.abs(np.asarray(p)).max()) for p in ABSTRACTION.regions.values())
    reach = 1e-12 * max(abs(point[0]), abs(point[1]), extent)
    return tuple(
        sorted(
            name
            for name, polygon in ABSTRACTION.regions.items()
            if shapely.dwithin(shapely.Polygon(polygon), shapely.Point(point), reach)
        )
    )


@given(
    st.sampled_from(CORNERS),
    st.sampled_from(CORNERS),
    st.sampled_from([0.0, 0.25, 0.5, 1.0]),
    st.sampled_from([0.0, 1e-13, -1e-13, 1e-6, -1e-6]),
)
def test_start_label_is_the_closure_rule(
    p: tuple[float, float], q: tuple[float, float], along: float, off: float
) -> None:
    point = (p[0] + along * (q[0] - p[0]) + off, p[1] + along * (q[1] - p[1]))
    assert start_point_label(ABSTRACTION, point) == _rule(point)


def test_a_corner_shared_by_three_regions_reads_all_three() -> None:
    assert start_point_label(ABSTRACTION, (4.0, 3.0)) == ("a", "b", "c")
