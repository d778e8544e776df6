"""The exact simulation's small products are ``ndarray.dot`` / ``np.dot`` (half of matmul's
per-call cost): on every shape it uses, the same bits as ``@``, and the matrix exponential the
same bits as its Horner definition written with ``@``."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from tlmpc.simulate.matrix import column_norm, expm_small, taylor_degree

FloatArray = npt.NDArray[np.float64]

_finite = st.floats(-1e3, 1e3, allow_nan=False, allow_subnormal=False)


def _matrix(shape: tuple[int, ...]) -> st.SearchStrategy[FloatArray]:
    return arrays(np.float64, shape, elements=_finite)


def _expm_with_matmul(matrix: FloatArray) -> FloatArray:
    """The scaling-and-squaring Horner series as it was written with ``@``."""
    norm = float(np.abs(matrix).sum(axis=0).max())
    squarings = max(0, math.ceil(math.log2(norm)) + 1) if norm > 0.5 else 0
    scale = 0.5**squarings
    scaled = matrix * scale
    degree = taylor_degree(norm * scale, 18)
    identity = np.eye(3)
    result = identity + scaled / degree
    for k in range(degree - 1, 0, -1):
        result = identity + (scaled @ result) / k
    for _ in range(squarings):
        result = result @ result
    return result


@settings(max_examples=300)
@given(_matrix((3, 3)), st.floats(1e-6, 40.0))
def test_expm_small_is_the_matmul_series_bit_for_bit(matrix: FloatArray, size: float) -> None:
    matrix = matrix / max(column_norm(matrix), 1e-300) * size  # norms 0 .. 40: squarings too
    assert expm_small(matrix).tobytes() == _expm_with_matmul(matrix).tobytes()


@settings(max_examples=200)
@given(_matrix((3, 3)), _matrix((3, 3)), _matrix((3,)), _matrix((2,)), _matrix((2,)))
def test_dot_is_matmul_on_the_small_shapes(
    a: FloatArray, b: FloatArray, v: FloatArray, n: FloatArray, x: FloatArray
) -> None:
    assert a.dot(b).tobytes() == (a @ b).tobytes()
    assert a.dot(a).tobytes() == (a @ a).tobytes()  # a squaring
    assert a.dot(v).tobytes() == (a @ v).tobytes()
    assert n.dot(x) == n @ x
    stack, other = np.empty((2, 3, 3)), np.empty((2, 3, 3))
    stack[0] = other[0] = b
    np.dot(a, stack[0], out=stack[1])  # into a chunk of powers, as the exit step writes them
    np.matmul(a, other[0], out=other[1])
    assert stack.tobytes() == other.tobytes()


@settings(max_examples=100)
@given(_matrix((128, 3)), _matrix((2,)), _matrix((2, 2)), _matrix((2,)), st.integers(1, 40))
def test_dot_is_matmul_on_the_grid_shapes(
    grid: FloatArray, normal: FloatArray, others: FloatArray, offsets: FloatArray, degree: int
) -> None:
    plane = grid[:, :2]  # a strided view, as the exit step reads its grid states
    assert plane.dot(normal).tobytes() == (plane @ normal).tobytes()
    heights = plane.dot(others.T) - offsets
    assert heights.tobytes() == (plane @ others.T - offsets).tobytes()
    assert np.maximum(heights[:, 0], heights[:, 1]).tobytes() == heights.max(axis=1).tobytes()
    powers = np.minimum(np.abs(grid[: degree + 1, 0]), 2.0) ** np.arange(degree + 1)
    coefficients = np.resize(grid, (degree + 1, 3))
    assert powers.dot(coefficients).tobytes() == (powers @ coefficients).tobytes()
    assert coefficients[:, :2].dot(normal).tobytes() == (coefficients[:, :2] @ normal).tobytes()
