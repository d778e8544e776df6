"""Small matrices of the exact flows: the augmented matrix of an affine law and its exponential.

An affine law u = K x + g is the linear flow of the augmented matrix M = [[K, g], [0, 0]] on
[x; 1], so [x(t); 1] = expm(tM) [x0; 1]. Every exact simulation (triangle steps, cell steps,
stays, the runtime's own steps) takes its exponentials here.
"""

from __future__ import annotations

import math

import numpy as np

from tlmpc.abstraction.model import FloatArray
from tlmpc.control.geometry import largest_of


def augmented(gain: FloatArray, offset: FloatArray) -> FloatArray:
    """[[K, g], [0, 0]]: the augmented matrix of the law u = K x + g."""
    matrix = np.zeros((3, 3))
    matrix[:2, :2] = gain
    matrix[:2, 2] = offset
    return matrix


#: 1/k! for the Taylor degrees used here.
_INVERSE_FACTORIALS = tuple(1.0 / math.factorial(k) for k in range(42))
#: Truncation error allowed in a series (far below rounding of an O(1) result).
_TAYLOR_TOLERANCE = 1e-18


def taylor_degree(radius: float, cap: int) -> int:
    """The first degree m <= cap with radius^(m+1)/(m+1)! <= 1e-18: where the exponential series
    of a matrix of norm ``radius`` is cut, the first neglected term is below 1e-18."""
    degree = 1
    while (
        degree < cap
        and radius ** (degree + 1) * _INVERSE_FACTORIALS[degree + 1] > _TAYLOR_TOLERANCE
    ):
        degree += 1
    return degree


#: The identity of the augmented matrices (read only: every use makes a new array).
_IDENTITY_3 = np.eye(3)
_IDENTITY_3.setflags(write=False)


def column_norm(matrix: FloatArray) -> float:
    """The 1-norm (largest column sum of |a_ij|) of a square matrix: the value of
    ``np.abs(matrix).sum(axis=0).max()``, summed as numpy sums (rows first to last) on
    Python floats, without numpy's per-call cost on a 3 x 3 matrix."""
    rows = matrix.tolist()
    sums = [abs(a) for a in rows[0]]
    for row in rows[1:]:
        sums = [total + abs(a) for total, a in zip(sums, row, strict=True)]
    return largest_of(sums)


def expm_small(matrix: FloatArray) -> FloatArray:
    """exp(A) of a small matrix by scaling and squaring with a Taylor polynomial (Horner form).

    The matrix is scaled to norm s <= 1/2 and the series is cut at the first degree m with
    s^(m+1)/(m+1)! <= 1e-18 (m <= 18; small steps need far fewer terms).  Squaring amplifies
    rounding to about 1e-11 relative for the gains that occur here (checked against scipy's
    ``expm`` in the tests), and it is many times faster than a general call.  The products
    are ``ndarray.dot``: the same BLAS product as ``@`` on these 2-D arrays (the same bits),
    at half of matmul's per-call cost on a 3 x 3 matrix.
    """
    norm = column_norm(matrix)
    squarings = max(0, math.ceil(math.log2(norm)) + 1) if norm > 0.5 else 0
    scale = 0.5**squarings
    scaled = matrix * scale
    degree = taylor_degree(norm * scale, 18)
    identity = _IDENTITY_3 if matrix.shape == (3, 3) else np.eye(matrix.shape[0])
    result = identity + scaled / degree
    for k in range(degree - 1, 0, -1):
        result = identity + scaled.dot(result) / k
    for _ in range(squarings):
        result = result.dot(result)
    return result


__all__ = ["augmented", "column_norm", "expm_small", "taylor_degree"]
