"""The loader's shortcuts for rect regions decide as the general checks do.

Two shortcuts: the schema's quick structural check of a region (``_plain_shape``, against the
mission schema's own ``shape`` definition, checked by jsonschema; NaN, which the reader
refuses before, is left to the full check) and ``check_shape``'s early
acceptance of a proper rect (against the same corners given as a point list, which takes the
general path: shapely's validity and area).
"""

from __future__ import annotations

import math
from typing import Any

import jsonschema
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.io.schema_check import load_schema
from tlmpc.mission.geometry import check_layout, check_shape
from tlmpc.mission.load import _plain_shape
from tlmpc.mission.shapes import CheckedShape

_EDGES = st.sampled_from(
    [0, 1, -1, 0.0, -0.0, 1e9, -1e9, 10**9, -(10**9), 10**9 + 1, 1e9 + 1e-6, True, False]
)
_ITEMS = st.one_of(
    _EDGES,
    st.integers(-(10**10), 10**10),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([None, "1", [1.0]]),
)


def _by_definition(shape: dict[str, Any]) -> bool:
    """A rect the schema accepts, NaN excluded (the reader refuses it before: Y005)."""
    rect = shape.get("rect")
    return (
        len(shape) == 1
        and isinstance(rect, list)
        and len(rect) == 4
        and all(_number(v) and not math.isnan(v) for v in rect)
        and _schema_says(shape)
    )


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _schema_says(shape: Any) -> bool:
    schema = load_schema("mission")
    validator = jsonschema.Draft202012Validator({"$defs": schema["$defs"], "$ref": "#/$defs/shape"})
    return bool(validator.is_valid(shape))


@given(
    st.lists(st.floats(-1e9, 1e9) | st.integers(-(10**9), 10**9), min_size=3, max_size=5),
    st.integers(0, 4),
    _ITEMS,
    st.booleans(),
)
def test_quick_rect_check_is_the_schemas_verdict(
    rect: list[Any], index: int, item: Any, extra_key: bool
) -> None:
    if index < len(rect):
        rect[index] = item  # one item of a plausible rect replaced by anything
    shape: dict[str, Any] = {"rect": rect}
    if extra_key:
        shape["name"] = "x"
    assert _plain_shape(shape) == _by_definition(shape)


@pytest.mark.parametrize("index", range(4))
@pytest.mark.parametrize(
    "item", [True, False, 1e9, -1e9, 10**9, 10**9 + 1, math.nan, math.inf, "1", None]
)
def test_quick_rect_check_at_the_edges(index: int, item: Any) -> None:
    rect: list[Any] = [0, 0.0, 1, 1.5]
    rect[index] = item
    assert _plain_shape({"rect": rect}) == _by_definition({"rect": rect})


def _no_position(path: tuple[str | int, ...]) -> tuple[int, int]:
    return (7, 3)


_COORDINATES = st.one_of(
    st.floats(-1e9, 1e9, allow_nan=False),
    st.sampled_from([0.0, 1.0, 1.0 + 1e-15, 1e-13, 1e9, -1e9, 0.5, 5e-7]),
)


@given(_COORDINATES, _COORDINATES, _COORDINATES, _COORDINATES)
def test_a_rect_is_checked_as_its_corners_are(x0: float, y0: float, x1: float, y1: float) -> None:
    rect, found = check_shape({"rect": [x0, y0, x1, y1]}, ("regions", "a"), "a", "f", _no_position)
    corners = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    general, expected = check_shape(corners, ("regions", "a"), "a", "f", _no_position)
    if not (x0 < x1 and y0 < y1):
        assert rect is None
        assert [p.code for p in found] == ["G001"]
        return
    assert [(p.code, p.line, p.col) for p in found] == [(p.code, 7, 3) for p in expected]
    assert (rect is None) == (general is None)
    if rect is not None and general is not None:
        assert rect.points == general.points


def test_a_sliver_rect_has_zero_area() -> None:
    rect, found = check_shape({"rect": [0, 0, 1, 1e-13]}, ("regions", "a"), "a", "f", _no_position)
    assert rect is None
    assert [(p.code, p.line, p.col) for p in found] == [("G003", 7, 3)]


_EDGE_XS = st.sampled_from([-0.5, 0.0, 1e-300, 3.0, 9.999999999999998, 10.0, 10.5])
_EDGE_YS = st.sampled_from([-1e-300, 0.0, 3.0, 5.999999999999999, 6.0, 6.5])


@given(
    st.lists(
        st.lists(st.tuples(_EDGE_XS, _EDGE_YS), min_size=3, max_size=5),
        max_size=6,
    ),
    st.tuples(_EDGE_XS, _EDGE_YS),
)
def test_regions_outside_a_rectangular_workspace_are_the_ones_with_a_vertex_outside(
    regions: list[list[tuple[float, float]]], start: tuple[float, float]
) -> None:
    boundary = CheckedShape(
        points=((0.0, 0.0), (10.0, 0.0), (10.0, 6.0), (0.0, 6.0)), polygon=None, path=("b",)
    )
    shapes = {
        f"r{i}": CheckedShape(points=tuple(points), polygon=None, path=("regions", f"r{i}"))
        for i, points in enumerate(regions)
    }
    found = check_layout(boundary, [], shapes, start, ("start",), "f", _no_position)
    outside = [
        name
        for name, shape in shapes.items()
        if any(not (0 <= x <= 10 and 0 <= y <= 6) for x, y in shape.points)
    ]
    assert [p.code for p in found if p.code == "G007"] == ["G007"] * len(outside)
    assert [p.message.split("'")[1] for p in found if p.code == "G007"] == outside
    assert any(p.code == "G009" for p in found) == (
        not (0 <= start[0] <= 10 and 0 <= start[1] <= 6)
    )


def test_a_region_above_a_wide_workspace_is_outside() -> None:
    # x within the workspace's height, y within its width: only the right axes tell.
    boundary = CheckedShape(
        points=((0.0, 0.0), (10.0, 0.0), (10.0, 6.0), (0.0, 6.0)), polygon=None, path=("b",)
    )
    high = CheckedShape(points=((0.0, 3.0), (3.0, 3.0), (3.0, 6.5)), polygon=None, path=("r",))
    found = check_layout(boundary, [], {"high": high}, (1.0, 1.0), ("s",), "f", _no_position)
    assert [p.code for p in found] == ["G007"]
