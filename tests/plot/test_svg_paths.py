"""Region outlines formatted in one numpy pass are the text of the point-by-point writer."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.render.layout import Canvas
from tlmpc.render.svg import _BATCH_FROM, _polygon_path, _polygon_paths

COORDINATE = st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False)
POLYGON = st.lists(st.tuples(COORDINATE, COORDINATE), min_size=0, max_size=6)


@pytest.mark.slow
@given(
    st.lists(POLYGON, min_size=_BATCH_FROM, max_size=3 * _BATCH_FROM),
    st.tuples(COORDINATE, COORDINATE, st.floats(1e-3, 1e4), st.floats(1e-3, 1e4)),
)
def test_batched_polygon_paths_equal_one_by_one(
    polygons: list[list[tuple[float, float]]], view: tuple[float, float, float, float]
) -> None:
    x0, y0, width, height = view
    canvas = Canvas.of((x0, y0, x0 + width, y0 + height))
    assert _polygon_paths(canvas, polygons) == [_polygon_path(canvas, p) for p in polygons]
