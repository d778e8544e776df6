"""The verifier's distance to a region's boundary, computed a coordinate at a time into
buffers, is bit for bit the row-wise definition: the same operations on the same numbers
(the reported robustness and the certificate's margin are printed to the last digit); the
containment test asked only inside a region's bounding box is shapely's on every point."""

from __future__ import annotations

import numpy as np
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.verify.robustness import INDEXED_EDGES, _indexed_ring_distance, _ring_distance

FloatArray = np.ndarray


def _row_wise(polygon: FloatArray, points: FloatArray) -> FloatArray:
    """Per edge: project each offset onto the edge, clamp to it, measure what is left."""
    best = np.full(len(points), np.inf)
    for start, end in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        edge = end - start
        length = float(edge @ edge)
        offset = points - start
        along = np.clip(offset @ edge / length, 0.0, 1.0) if length > 0 else np.zeros(len(points))
        gap = offset - along[:, None] * edge
        np.minimum(best, np.hypot(gap[:, 0], gap[:, 1]), out=best)
    return best


coordinate = st.floats(-1e4, 1e4, allow_nan=False, allow_subnormal=False)


@given(
    st.lists(st.tuples(coordinate, coordinate), min_size=3, max_size=9),
    st.lists(st.tuples(coordinate, coordinate), min_size=1, max_size=300),
    st.booleans(),
)
def test_ring_distance_is_the_row_wise_definition_bit_for_bit(
    corners: list[tuple[float, float]], probes: list[tuple[float, float]], repeat: bool
) -> None:
    ring = np.asarray(corners, dtype=np.float64)
    if repeat:
        ring = np.vstack([ring[:1], ring])  # a zero-length edge
    points = np.asarray(probes + corners, dtype=np.float64)  # the corners themselves too
    assert _ring_distance(ring, points).tobytes() == _row_wise(ring, points).tobytes()


def test_ring_distance_on_a_trace_sized_array_is_the_row_wise_definition() -> None:
    # Long arrays go through numpy's blocked loops and BLAS's blocked product: the same
    # (n, 2) layout gives the same numbers there too.
    rng = np.random.default_rng(7)
    points = rng.uniform(-50.0, 150.0, (100_003, 2))
    ring = np.array([[10.0, 10.0], [12.5, 10.0], [12.5, 13.25], [10.0, 13.25]])
    got = _ring_distance(ring, points)
    assert got.tobytes() == _row_wise(ring, points).tobytes()
    # and it is the distance: a point's distance to an axis-aligned rectangle's boundary
    x, y = points[:, 0], points[:, 1]
    dx = np.maximum(np.maximum(10.0 - x, x - 12.5), 0.0)
    dy = np.maximum(np.maximum(10.0 - y, y - 13.25), 0.0)
    outside = (dx > 0) | (dy > 0)
    inner = np.minimum.reduce([x - 10.0, 12.5 - x, y - 10.0, 13.25 - y])
    expected = np.where(outside, np.hypot(dx, dy), inner)
    assert np.allclose(got, expected, rtol=0, atol=1e-12)


@given(
    st.lists(st.tuples(coordinate, coordinate), min_size=3, max_size=9),
    st.lists(st.tuples(coordinate, coordinate), min_size=0, max_size=200),
    st.floats(0.0, 1.0),
)
def test_containment_asked_in_the_bounding_box_only_is_shapelys(
    corners: list[tuple[float, float]], probes: list[tuple[float, float]], share: float
) -> None:
    import shapely

    from tlmpc.verify.robustness import _contains

    ring = np.asarray(corners, dtype=np.float64)
    shape = shapely.Polygon(ring)
    # corners, edge midpoints, the centroid and points between a corner and the centroid
    middle = ring.mean(axis=0)
    extra = [
        *ring,
        *((ring + np.roll(ring, -1, axis=0)) / 2),
        middle,
        ring[0] * share + middle * (1 - share),
    ]
    points = np.asarray([*probes, *extra], dtype=np.float64).reshape(-1, 2)
    expected = shapely.contains_xy(shape, points[:, 0], points[:, 1])
    assert _contains(shape, ring, points).tolist() == expected.tolist()


def test_ring_distance_across_block_boundaries_is_the_row_wise_definition() -> None:
    # The points go a block at a time: every block's rows (the last, shorter one too) give
    # the numbers of the whole array's.
    from tlmpc.verify.robustness import RING_BLOCK

    rng = np.random.default_rng(11)
    ring = rng.uniform(-3.0, 3.0, (7, 2))
    for count in (1, RING_BLOCK - 1, RING_BLOCK, RING_BLOCK + 1, 3 * RING_BLOCK + 5):
        points = rng.uniform(-20.0, 20.0, (count, 2))
        assert _ring_distance(ring, points).tobytes() == _row_wise(ring, points).tobytes()


@settings(max_examples=max(10, settings().max_examples // 5), deadline=None)
@given(
    st.integers(INDEXED_EDGES + 1, 3 * INDEXED_EDGES),
    st.integers(0, 2**32 - 1),
    st.floats(0.0, 0.9),
)
def test_a_large_ring_through_its_index_is_geos_distance_bit_for_bit(
    corners: int, seed: int, jagged: float
) -> None:
    """Star-shaped rings of many corners (jagged: radii that vary), probed inside, outside,
    on their corners and on their edges: the index finds GEOS's own distance to the ring."""
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, corners))
    radii = 2.0 * (1.0 - jagged * rng.uniform(0.0, 1.0, corners))
    ring = np.stack([5.0 + radii * np.cos(angles), 5.0 + radii * np.sin(angles)], axis=1)
    polygon = shapely.Polygon(ring)
    if not polygon.is_valid:
        return
    halfway = (ring + np.roll(ring, -1, axis=0)) / 2.0
    probes = np.concatenate([rng.uniform(0.0, 10.0, (2000, 2)), ring[::7], halfway[::5]])
    geoms = shapely.points(probes)
    expected = shapely.distance(polygon.exterior, geoms)
    assert np.array_equal(_indexed_ring_distance(polygon.exterior, geoms), expected)
