"""Many regions: the scene boxes them in one numpy pass; the result is the definition's.

A region is drawn when its bounding box meets the view (closed intervals); its colour follows
its place among all regions sorted by name.  The expected scene is computed here from that
definition one region at a time, and the SVG written from the scene's own point array must
be the SVG written from the polygons.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from tlmpc.render.scene import _BATCH_FROM, REGION_COLOURS, build_scene
from tlmpc.render.svg import render_svg

# Thousandths as integers: the same values as rounded floats at a third of the entropy, so a
# list of 64 to 128 regions fits hypothesis's buffer on every hypothesis release.
COORDINATE = st.integers(-50_000, 50_000).map(lambda v: v / 1000)
RING = st.lists(st.tuples(COORDINATE, COORDINATE), min_size=3, max_size=6)
VIEW = st.tuples(COORDINATE, COORDINATE, st.floats(0.5, 60.0), st.floats(0.5, 60.0))


def _mission(rings: list[list[tuple[float, float]]]) -> dict[str, Any]:
    return {
        "format": "tlmpc.mission/1",
        "name": "many-regions",
        "formula": "F r0",
        "workspace": {"boundary": [[-60.0, -60.0], [60.0, -60.0], [60.0, 60.0], [-60.0, 60.0]]},
        "regions": {f"r{i}": [list(p) for p in ring] for i, ring in enumerate(rings)},
        "robot": {"start": [0.0, 0.0], "max_speed": 1.0},
        "options": {"boundary": "right"},
    }


def _meets(ring: list[tuple[float, float]], view: tuple[float, float, float, float]) -> bool:
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    x0, y0, x1, y1 = view
    return min(xs) <= x1 and max(xs) >= x0 and min(ys) <= y1 and max(ys) >= y0


#: Rooms left of, right of, below, above and inside the window (0, 0)-(10, 10), and one on it.
_AROUND = [
    [(-20.0 + dx, 2.0 + dy), (-15.0 + dx, 2.0 + dy), (-15.0 + dx, 6.0 + dy)]
    for dx, dy in [(0.0, 0.0), (40.0, 0.0), (17.0, -20.0), (17.0, 20.0), (19.0, 0.0), (25.0, 0.0)]
]


@settings(
    max_examples=max(10, settings().max_examples // 5),
    deadline=None,
    # Many regions are the point (the batched path starts at _BATCH_FROM): an overrun draw is
    # retried, never a reason to stop.
    suppress_health_check=[HealthCheck.data_too_large],
)
@given(
    st.lists(RING, min_size=_BATCH_FROM, max_size=2 * _BATCH_FROM),
    st.one_of(st.none(), VIEW),
)
@example(_AROUND * (_BATCH_FROM // len(_AROUND) + 1), (0.0, 0.0, 10.0, 10.0))
def test_batched_regions_are_the_one_by_one_definition(
    rings: list[list[tuple[float, float]]], window: tuple[float, float, float, float] | None
) -> None:
    zoom = None
    if window is not None:
        x0, y0, width, height = window
        zoom = (x0, y0, x0 + width, y0 + height)
    mission = _mission(rings)
    scene = build_scene({"mission.json": mission}, zoom=zoom)
    ordered = sorted(mission["regions"].items())
    expected = [
        (name, tuple((float(x), float(y)) for x, y in ring), REGION_COLOURS[i % 9])
        for i, (name, ring) in enumerate(ordered)
        if _meets([(p[0], p[1]) for p in ring], scene.view)
    ]
    assert [(r.name, r.polygon, r.colour) for r in scene.regions] == expected
    if scene.region_points is not None:
        assert scene.region_points.tolist() == [list(p) for _, ring, _ in expected for p in ring]
    # the SVG from the scene's point array is the SVG from its polygons
    without = dataclasses.replace(scene, region_points=None)
    assert render_svg(scene) == render_svg(without)


def test_a_non_finite_coordinate_takes_the_one_by_one_path() -> None:
    rings = [[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)] for _ in range(_BATCH_FROM)]
    rings[3] = [(0.0, 0.0), (float("inf"), 0.0), (1.0, 1.0)]
    scene = build_scene({"mission.json": _mission(rings)}, zoom=(-1.0, -1.0, 2.0, 2.0))
    assert scene.region_points is None
    assert len(scene.regions) == _BATCH_FROM
