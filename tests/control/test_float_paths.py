"""The per-step arithmetic done on Python floats against its definition on numpy arrays.

The controllers and the exact simulation compute triangle geometry, affine frames, 1-norms and
angle gaps on Python floats (numpy's per-call cost on 2-vectors dominated those stages).  Each
is compared here with its definition written with numpy arrays, the way the stages computed
them before, on triangles of every size and distance from the origin.

Where both sides run the same numpy operation on the same inputs (the affine frame's solve, the
column sums) the arrays are equal.  A 2-vector's norm and dot product are IEEE operations in a
fixed order on Python floats, so the stages give the same bytes on every machine; numpy hands
them to BLAS, whose kernels fuse multiply and add on some processors (AVX-512, FMA), so there
the definition itself differs in the last bit.  Those are compared at a stated tolerance: a few
units in the last place of the terms summed.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, example, given
from hypothesis import strategies as st

from tlmpc.abstraction.model import FloatArray
from tlmpc.control.geometry import (
    affine_law,
    half_plane_feasible,
    largest_of,
    triangle_geometry,
)
from tlmpc.simulate.matrix import column_norm

MAGNITUDE = st.floats(-12, 12)  # decimal exponents of sizes and offsets
EPS = float(np.finfo(np.float64).eps)
#: Units in the last place allowed between the Python-float path and numpy's BLAS path.
ULPS = 8


@st.composite
def triangles(draw: st.DrawFn) -> FloatArray:
    """A counter-clockwise triangle of any size, anywhere (not degenerate)."""
    exponent = draw(MAGNITUDE)
    size = 10.0**exponent
    # at most a million sizes from the origin: farther, rounding flattens the triangle
    shift = 10.0 ** draw(st.floats(exponent - 6, exponent + 6)) * np.array(
        [draw(st.floats(-1, 1)), draw(st.floats(-1, 1))]
    )
    corners = np.array(
        [[draw(st.floats(-1, 1)), draw(st.floats(-1, 1))] for _ in range(3)], dtype=np.float64
    )
    first, second = corners[1] - corners[0], corners[2] - corners[0]
    area = first[0] * second[1] - first[1] * second[0]
    if abs(area) < 1e-3:
        corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.25, 0.75]])
    elif area < 0:
        corners = corners[::-1].copy()
    return np.asarray(corners * size + shift, dtype=np.float64)


def geometry_by_arrays(v: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Normals, offsets and heights with numpy arrays, as the definition reads."""
    normals, offsets, heights = np.empty((3, 2)), np.empty(3), np.empty(3)
    for i in range(3):
        a, b = v[(i + 1) % 3], v[(i + 2) % 3]
        edge = b - a
        normal = np.array([edge[1], -edge[0]])
        normal /= np.linalg.norm(normal)
        normals[i], offsets[i] = normal, normal @ a
        heights[i] = offsets[i] - normal @ v[i]
    return normals, offsets, heights


def affine_law_by_arrays(v: FloatArray, w: FloatArray) -> tuple[FloatArray, FloatArray]:
    center = v.mean(axis=0)
    size = float(np.abs(v - center).max())
    system = np.hstack([(v - center) / size, np.ones((3, 1))])
    solution = np.linalg.solve(system, w)
    gain = np.ascontiguousarray(solution[:2].T / size)
    return gain, solution[2] - gain @ center


def half_plane_by_arrays(normals: list[FloatArray]) -> bool:
    if len(normals) <= 1:
        return True
    angles = np.sort(np.array([np.arctan2(a[1], a[0]) for a in normals]))
    gaps = np.diff(np.concatenate([angles, [angles[0] + 2 * np.pi]]))
    return bool(gaps.max() > np.pi + 1e-9)


@given(triangles())
@example(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]))
@example(np.array([[1e6, 1e6], [1e6 + 1e-3, 1e6], [1e6, 1e6 + 1e-3]]))
def test_triangle_geometry_is_the_array_definition(v: FloatArray) -> None:
    geometry = triangle_geometry(v)
    normals, offsets, heights = geometry_by_arrays(v)
    # Each value is a short sum of products: rounded (with or without fused multiply-adds)
    # within a few ulps of the largest term, here bounded by ULPS units of the coordinates'
    # magnitude.  Unit normals: of 1.
    reach = np.abs(v).max() + float(np.abs(v[:, None, :] - v[None, :, :]).max())
    assert np.abs(geometry.normals - normals).max() <= ULPS * EPS
    assert np.abs(geometry.offsets - offsets).max() <= ULPS * EPS * reach
    assert np.abs(geometry.heights - heights).max() <= ULPS * EPS * reach
    # and the definition itself: unit outward normals, each facet on its line, positive heights
    assert np.allclose(np.linalg.norm(geometry.normals, axis=1), 1.0)
    assert np.all(geometry.heights > 0)


def test_a_degenerate_edge_gives_numpy_nan_not_an_exception() -> None:
    v = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 1.0]])
    with np.errstate(invalid="ignore", divide="ignore"):
        geometry = triangle_geometry(v)
    assert np.isnan(geometry.normals[2]).all()


@given(triangles(), st.lists(st.floats(-10, 10), min_size=6, max_size=6))
def test_affine_law_is_the_array_definition(v: FloatArray, speeds: list[float]) -> None:
    w = np.array(speeds, dtype=np.float64).reshape(3, 2)
    gain, offset = affine_law(v, w)
    expected_gain, expected_offset = affine_law_by_arrays(v, w)
    assert np.array_equal(gain, expected_gain)
    assert np.array_equal(offset, expected_offset)


@given(st.lists(st.floats(-math.pi, math.pi), max_size=6))
def test_half_plane_test_is_the_array_definition(angles: list[float]) -> None:
    normals = [np.array([math.cos(a), math.sin(a)]) for a in angles]
    # numpy's arctan2 may be a vectorised kernel a few ulps from math.atan2: a widest gap
    # within rounding of the threshold can go either way, and is not a disagreement.
    directions = sorted(math.atan2(n[1], n[0]) for n in normals)
    gaps = [b - a for a, b in zip(directions, directions[1:] + directions[:1], strict=True)]
    assume(all(abs((gap % (2 * math.pi)) - (math.pi + 1e-9)) > 1e-12 for gap in gaps))
    assert half_plane_feasible(normals) == half_plane_by_arrays(normals)
    as_floats: list[tuple[float, float]] = [(float(n[0]), float(n[1])) for n in normals]
    assert half_plane_feasible(as_floats) == half_plane_by_arrays(normals)


def test_half_plane_test_on_known_fans() -> None:
    def unit(degrees: float) -> FloatArray:
        return np.array([math.cos(math.radians(degrees)), math.sin(math.radians(degrees))])

    assert half_plane_feasible([unit(0), unit(90), unit(170)])
    assert not half_plane_feasible([unit(0), unit(90), unit(190)])
    assert not half_plane_feasible([unit(-100), unit(0), unit(100)])  # wraps around 180°


@given(
    st.integers(2, 4).flatmap(
        lambda n: st.lists(
            st.floats(-1e6, 1e6, allow_nan=False, allow_subnormal=False),
            min_size=n * n,
            max_size=n * n,
        )
    )
)
def test_column_norm_is_numpys(entries: list[float]) -> None:
    n = math.isqrt(len(entries))
    matrix = np.array(entries, dtype=np.float64).reshape(n, n)
    assert column_norm(matrix) == float(np.abs(matrix).sum(axis=0).max())


def test_column_norm_propagates_nan_as_numpy_does() -> None:
    matrix = np.array([[1.0, np.nan, 0.0], [2.0, 3.0, 0.0], [0.0, 0.0, 5.0]])
    assert math.isnan(column_norm(matrix))
    assert math.isnan(float(np.abs(matrix).sum(axis=0).max()))


@given(
    st.lists(
        st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.just(math.nan)),
        min_size=1,
        max_size=6,
    )
)
def test_largest_of_is_numpys_max(values: list[float]) -> None:
    expected = float(np.max(np.array(values)))
    got = largest_of(values)
    assert got == expected or (math.isnan(got) and math.isnan(expected))


def test_non_finite_inputs_take_numpys_path() -> None:
    point = np.array([[1.0, 1.0], [1.0, 1.0], [1.0, 1.0]])
    with np.errstate(invalid="ignore", divide="ignore"):
        gain, offset = affine_law(point, np.ones((3, 2)))
        expected_gain, expected_offset = affine_law_by_arrays(point, np.ones((3, 2)))
    assert np.array_equal(gain, expected_gain, equal_nan=True)
    assert np.array_equal(offset, expected_offset, equal_nan=True)
    normals = [np.array([math.nan, 0.0]), np.array([1.0, 0.0])]
    assert half_plane_feasible(normals) is False
    with np.errstate(invalid="ignore"):
        assert half_plane_by_arrays(normals) is False
