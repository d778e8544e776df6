"""The plan pictures: what plan.svg shows and where, drawn from hand-made artifacts."""

from __future__ import annotations

import math
import re
from typing import Any
from xml.etree import ElementTree

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.render.plot import render_svg
from tlmpc.render.scene import MAX_MESH_TRIANGLES, arc_length_path, build_scene, viridis

SVG = "{http://www.w3.org/2000/svg}"


def _mission(holes: list[list[list[float]]] | None = None) -> dict[str, Any]:
    return {
        "format": "tlmpc.mission/1",
        "name": "figure-test",
        "formula": "F goal & G !lane",
        "workspace": {
            "boundary": [[0.0, 0.0], [10.0, 0.0], [10.0, 4.0], [0.0, 4.0]],
            "holes": holes or [],
        },
        "regions": {
            "goal": [[8.0, 1.0], [9.0, 1.0], [9.0, 2.0], [8.0, 2.0]],
            "lane": [[4.0, 0.0], [5.0, 0.0], [5.0, 0.5], [4.0, 0.5]],
            "dock": [[0.5, 0.5], [2.0, 0.5], [2.0, 2.0], [0.5, 2.0]],
        },
        "robot": {"start": [1.0, 1.0], "max_speed": 1.0},
        "options": {"boundary": "right"},
    }


def _trace(points: list[list[float]]) -> dict[str, Any]:
    return {"format": "tlmpc.trace/1", "points": points}


def _numbers(d: str) -> list[float]:
    return [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", d)]


@given(
    st.lists(
        st.tuples(st.floats(-1e3, 1e3, allow_nan=False), st.floats(-1e3, 1e3, allow_nan=False)),
        min_size=1,
        max_size=60,
    )
)
def test_arc_length_fractions_follow_the_distance_travelled(xy: list[tuple[float, float]]) -> None:
    samples = [[float(i), x, y] for i, (x, y) in enumerate(xy)]
    path = arc_length_path(samples)
    assert path is not None
    steps = np.hypot(np.diff([p[0] for p in xy]), np.diff([p[1] for p in xy]))
    total = float(steps.sum())
    assert math.isclose(path.length, total, rel_tol=1e-9, abs_tol=1e-9)
    assert path.fractions[0] == 0.0
    assert all(b >= a for a, b in zip(path.fractions, path.fractions[1:], strict=False))
    if total > 0:
        assert math.isclose(path.fractions[-1], 1.0, rel_tol=1e-12)
        expected = np.concatenate([[0.0], np.cumsum(steps)]) / total
        assert np.allclose(path.fractions, expected, atol=1e-9)


def test_a_final_stay_takes_no_colour_range() -> None:
    # A straight 8 m run, then 500 samples standing still: by time the stay would take
    # most of the scale; by distance travelled it is the last colour only.
    run = [[0.1 * i, 1.0 + 0.08 * i, 1.0] for i in range(101)]
    stay = [[10.0 + 0.1 * i, 9.0, 1.0] for i in range(1, 501)]
    svg = render_svg({"mission.json": _mission(), "trace.json": _trace(run + stay)}).decode()
    root = ElementTree.fromstring(svg)
    colours = [
        e.get("stroke")
        for e in root.iter(f"{SVG}path")
        if e.get("stroke-width") == "2.0" and e.get("stroke", "").startswith("#")
    ]
    # Evenly spaced samples along a straight line: every colour step is used about equally.
    assert len(colours) >= 40
    assert colours[0] == viridis(0.5 / 48)
    assert colours[-1] == viridis(47.5 / 48)
    assert len(set(colours)) == len(colours)


def test_legend_and_colour_scale_are_beside_the_map_not_on_it() -> None:
    svg = render_svg({"mission.json": _mission(), "trace.json": _trace([[0, 1, 1], [1, 8.5, 1.5]])})
    root = ElementTree.fromstring(svg)
    clip = next(root.iter(f"{SVG}clipPath"))[0]
    map_right = float(clip.get("x", "0")) + float(clip.get("width", "0"))
    legend_texts = [t for t in root if t.tag == f"{SVG}text"]  # top level: outside the map
    labels = {t.text for t in legend_texts}
    assert {"trajectory, coloured by", "start", "task region"} <= labels or {
        "trajectory, coloured by",
        "start",
        "region",
    } <= labels
    for text in legend_texts:
        if text.text in ("start", "trajectory, coloured by", "region", "0"):
            assert float(text.get("x", "0")) > map_right


def test_every_region_is_named_and_names_are_drawn_over_the_start() -> None:
    svg = render_svg({"mission.json": _mission()}).decode()
    for name in ("goal", "lane", "dock"):
        assert f">{name}</text>" in svg
    # The start (inside dock) comes before the names in paint order: names stay readable.
    assert svg.index("<circle") < svg.index(">dock</text>")


def _hole_paths(svg: bytes) -> list[ElementTree.Element]:
    root = ElementTree.fromstring(svg)
    return [e for e in root.iter(f"{SVG}path") if e.get("fill") == "#9a9a9a"]


def test_a_narrow_door_and_a_thin_wall_stay_visible() -> None:
    # Two walls 1 mm thick leave a door 2 mm wide on a 10 m map.
    wall_a = [[5.0, 0.0], [5.001, 0.0], [5.001, 1.999], [5.0, 1.999]]
    wall_b = [[5.0, 2.001], [5.001, 2.001], [5.001, 4.0], [5.0, 4.0]]
    artifacts = {"mission.json": _mission([wall_a, wall_b])}
    (holes,) = _hole_paths(render_svg(artifacts))
    assert float(holes.get("stroke-width", "0")) >= 1.0  # a 0.1-pixel wall still shows
    zoomed = render_svg(artifacts, zoom=(4.99, 1.99, 5.01, 2.01))
    (holes,) = _hole_paths(zoomed)
    ys = _numbers(holes.get("d", ""))[1::2]
    root = ElementTree.fromstring(zoomed)
    clip = next(root.iter(f"{SVG}clipPath"))[0]
    top = float(clip.get("y", "0"))
    bottom = top + float(clip.get("height", "0"))
    # Inside the window only the door's two edges (y = 1.999 and 2.001) have corners.
    edges = sorted({y for y in ys if top <= y <= bottom})
    assert len(edges) == 2
    assert edges[1] - edges[0] >= 50.0  # the 2 mm door spans many pixels when zoomed


def test_zoom_keeps_only_the_mesh_in_the_window() -> None:
    n = 20
    vertices = [[10.0 * i / n, 4.0 * j / n] for j in range(n + 1) for i in range(n + 1)]
    triangles = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            triangles += [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
    abstraction = {"vertices": vertices, "triangles": triangles}
    full = build_scene({"mission.json": _mission(), "abstraction.json": abstraction})
    window = (0.0, 0.0, 2.0, 0.8)
    part = build_scene({"mission.json": _mission(), "abstraction.json": abstraction}, zoom=window)
    # Unique edges of a structured grid: n(n+1) horizontal, n(n+1) vertical, n^2 diagonal.
    assert len(full.mesh_edges) == 2 * n * (n + 1) + n * n
    assert 0 < len(part.mesh_edges) < len(full.mesh_edges) / 10
    for x0, y0, x1, y1 in part.mesh_edges:
        # Every edge drawn belongs to a triangle touching the window (cells are 0.5 x 0.2).
        assert min(x0, x1) <= window[2] + 0.5 + 1e-9
        assert min(y0, y1) <= window[3] + 0.2 + 1e-9
    assert [r.name for r in part.regions] == ["dock"]


def test_a_dense_mesh_is_left_out_and_said_so() -> None:
    n = 110  # 24,200 triangles > the limit
    vertices = [[float(i), float(j)] for j in range(n + 1) for i in range(n + 1)]
    triangles = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            triangles += [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
    assert len(triangles) > MAX_MESH_TRIANGLES
    scene = build_scene(
        {
            "mission.json": _mission(),
            "abstraction.json": {"vertices": vertices, "triangles": triangles},
        },
        zoom=(0.0, 0.0, 110.0, 110.0),
    )
    assert len(scene.mesh_edges) == 0
    assert scene.mesh_omitted == len(triangles)
    assert b"triangles not drawn" in render_svg(
        {
            "mission.json": _mission(),
            "abstraction.json": {"vertices": vertices, "triangles": triangles},
        },
        zoom=(0.0, 0.0, 110.0, 110.0),
    )


def test_violations_are_marked_where_they_happen() -> None:
    verdict = {
        "format": "tlmpc.verdict/1",
        "satisfied": False,
        "counterexample": {
            "conjunct": "G !lane",
            "time": 3.0,
            "position": [4.5, 0.25],
            "message": "enters lane at t = 3",
        },
        "workspace_violation": None,
    }
    scene = build_scene({"mission.json": _mission()}, verdict=verdict)
    assert [v.position for v in scene.violations] == [(4.5, 0.25)]
    svg = render_svg({"mission.json": _mission()}, verdict=verdict).decode()
    assert "violation 1" in svg
    assert "enters lane at t = 3" in svg
