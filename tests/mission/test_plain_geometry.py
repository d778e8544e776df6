"""The pure-Python geometry shortcuts answer only what shapely (the oracle) answers.

Random rings on small grids (so that collinear points, repeated vertices, spikes, touching
and crossing edges are common) and with float noise; a shortcut may decline (None), never
disagree.  Then the whole checks: ``check_shape`` and ``check_layout`` report the same
diagnostics with the shortcuts as with shapely alone.
"""

from __future__ import annotations

from typing import Any

import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import Point as ShapelyPoint
from shapely.geometry import Polygon as ShapelyPolygon

from tlmpc.mission import plain_geometry
from tlmpc.mission.geometry import check_layout, check_shape

coordinates = st.one_of(
    st.integers(0, 4).map(float),
    st.integers(0, 4).map(lambda v: v + 1e-9),
    st.floats(0, 4, allow_nan=False),
    st.sampled_from([0.1, 0.2, 0.3, 1 / 3, 2 / 3, 1e-17]),
)
points = st.tuples(coordinates, coordinates)
rings = st.lists(points, min_size=3, max_size=9)


def _dedupe(ring: list[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    kept: list[tuple[float, float]] = []
    for point in ring:
        if not kept or kept[-1] != point:
            kept.append(point)
    if len(kept) > 1 and kept[0] == kept[-1]:
        kept.pop()
    return tuple(kept)


@given(rings)
def test_certainly_simple_only_when_shapely_says_valid(ring: list[tuple[float, float]]) -> None:
    ring_points = _dedupe(ring)
    if len(set(ring_points)) < 3:
        return
    if plain_geometry.certainly_simple(ring_points):
        assert ShapelyPolygon(ring_points).is_valid, ring_points


def test_certainly_simple_answers_on_ordinary_shapes() -> None:
    assert plain_geometry.certainly_simple(((0, 0), (4, 0), (4, 4), (2, 1), (0, 4)))
    assert plain_geometry.certainly_simple(((0, 0), (2, 0), (4, 0), (4, 4)))  # a straight vertex
    assert plain_geometry.certainly_simple(((0, 0), (4, 0), (4, 4), (0, 4), (2, 4), (2, 2))) is None
    assert plain_geometry.certainly_simple(((0, 0), (4, 4), (4, 0), (0, 4))) is None  # bow tie


@given(rings)
def test_shoelace_area_is_shapelys(ring: list[tuple[float, float]]) -> None:
    ring_points = _dedupe(ring)
    if len(set(ring_points)) < 3:
        return
    area = plain_geometry.shoelace_area(ring_points)
    assert (
        abs(area - ShapelyPolygon(ring_points).area * (1 if area >= 0 else -1))
        <= 1e-12 + (1e-12 * abs(area))
        or not ShapelyPolygon(ring_points).is_valid
    )


@given(st.lists(points, min_size=4, max_size=4), st.lists(points, min_size=1, max_size=6))
def test_rectangle_containment_is_shapelys(
    corners: list[tuple[float, float]], inner: list[tuple[float, float]]
) -> None:
    rect = plain_geometry.axis_rectangle(tuple(corners))
    if rect is None:
        return
    outer = ShapelyPolygon(corners)
    assert outer.is_valid
    assert shapely.equals(outer, shapely.box(*rect))
    inside = plain_geometry.inside_rectangle(inner, rect)
    if len(set(inner)) >= 3 and ShapelyPolygon(inner).is_valid and ShapelyPolygon(inner).area:
        assert inside == outer.covers(ShapelyPolygon(inner))
    assert plain_geometry.inside_rectangle(inner[:1], rect) == outer.covers(ShapelyPoint(inner[0]))


def test_a_bow_tie_with_a_rectangles_corners_is_no_rectangle() -> None:
    assert plain_geometry.axis_rectangle(((0, 0), (1, 1), (1, 0), (0, 1))) is None
    assert plain_geometry.axis_rectangle(((0, 0), (1, 0), (1, 1), (0, 1))) == (0, 0, 1, 1)


def _codes(found: list[Any]) -> list[tuple[str, str]]:
    return [(d.code, d.message) for d in found]


def _locate(path: Any) -> tuple[int, int]:
    return (1, 1)


@given(rings)
def test_check_shape_reports_as_with_shapely_alone(ring: list[tuple[float, float]]) -> None:
    fast = check_shape([list(p) for p in ring], ("r",), "region 'r'", "m", _locate)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(plain_geometry, "certainly_simple", lambda points: None)
        slow = check_shape([list(p) for p in ring], ("r",), "region 'r'", "m", _locate)
    assert _codes(fast[1]) == _codes(slow[1])
    assert (fast[0] is None) == (slow[0] is None)


@given(
    st.tuples(coordinates, coordinates, coordinates, coordinates),
    st.lists(rings, max_size=3),
    points,
)
def test_check_layout_reports_as_with_shapely_alone(
    box: tuple[float, float, float, float],
    shapes: list[list[tuple[float, float]]],
    start: tuple[float, float],
) -> None:
    x0, x1 = sorted((box[0], box[2]))
    y0, y1 = sorted((box[1], box[3]))
    boundary, _ = check_shape({"rect": [x0, y0, x1, y1]}, ("b",), "b", "m", _locate)
    regions = {}
    for index, ring in enumerate(shapes):
        checked, _ = check_shape([list(p) for p in ring], ("r", index), "r", "m", _locate)
        if checked is not None:
            regions[f"r{index}"] = checked
    fast = check_layout(boundary, [], regions, start, ("s",), "m", _locate)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(plain_geometry, "axis_rectangle", lambda points: None)
        slow = check_layout(boundary, [], regions, start, ("s",), "m", _locate)
    assert _codes(fast) == _codes(slow)
