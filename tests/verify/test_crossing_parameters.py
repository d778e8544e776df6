"""Where each segment of a path crosses a region's boundary, against shapely's intersection.

The oracle intersects every segment with every boundary on its own (no spatial index, no
vectorised solve) and reads the crossing points' parameters along the segment.
"""

from __future__ import annotations

import itertools

import numpy as np
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tlmpc.verify.pieces import MERGE, crossing_parameters

coordinate = st.integers(min_value=0, max_value=8).map(float)


def _oracle(points: np.ndarray, polygons: list[np.ndarray]) -> list[list[float]]:
    found: list[list[float]] = []
    for a, b in itertools.pairwise(points.tolist()):
        segment = shapely.LineString([a, b])
        r = np.subtract(b, a)
        parameters: list[float] = []
        for polygon in polygons:
            meet = shapely.intersection(segment, shapely.Polygon(polygon).exterior)
            coords = [c for part in shapely.get_parts(meet) for c in part.coords]
            parameters += [float(np.dot(np.subtract(c, a), r) / np.dot(r, r)) for c in coords]
        inside = sorted(v for v in parameters if MERGE < v < 1.0 - MERGE)
        merged: list[float] = []
        for v in inside:
            if not merged or v - merged[-1] > 1e-9:
                merged.append(v)
        found.append(merged)
    return found


@settings(max_examples=80, deadline=None)
@example(  # the first segment crosses the second square before the first, the others nothing
    path=[(0.0, 2.0), (8.0, 2.0), (8.0, 8.0), (0.0, 8.0)],
    squares=[(5.0, 1.0, 1.0), (1.0, 1.0, 2.0)],
)
@given(
    path=st.lists(st.tuples(coordinate, coordinate), min_size=2, max_size=12).filter(
        lambda p: all(a != b for a, b in itertools.pairwise(p))
    ),
    squares=st.lists(
        st.tuples(coordinate, coordinate, st.integers(min_value=1, max_value=4).map(float)),
        min_size=1,
        max_size=3,
    ),
)
def test_crossings_are_the_boundary_intersections(
    path: list[tuple[float, float]], squares: list[tuple[float, float, float]]
) -> None:
    # squares offset by a quarter: crossings at interior parameters, collinear runs possible
    polygons = [
        np.array([[x, y], [x + s, y], [x + s, y + s], [x, y + s]], dtype=np.float64) + 0.25
        for x, y, s in squares
    ]
    points = np.array(path, dtype=np.float64)
    found = crossing_parameters(points, polygons)
    expected = _oracle(points, polygons)
    assert len(found) == len(expected)
    for mine, theirs in zip(found, expected, strict=True):
        assert mine == sorted(mine)
        assert len(mine) == len(theirs), (mine, theirs)
        assert np.allclose(mine, theirs, rtol=0.0, atol=1e-9)
