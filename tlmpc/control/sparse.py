"""The few sparse matrices the controller program needs, in numpy alone.

Clarabel reads a matrix through its ``data``, ``indices``, ``indptr``, ``nnz`` and ``shape``
attributes (compressed sparse columns); :class:`CscMatrix` is exactly that, so building the
program does not import scipy.sparse (a tenth of a second of every compile).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True, slots=True)
class Triplets:
    """A sparse matrix as (row, column, value) triplets, one per stored entry (duplicates
    summed, explicit zeros kept), in row-major order."""

    rows: IntArray
    cols: IntArray
    values: FloatArray
    shape: tuple[int, int]

    @staticmethod
    def build(rows: object, cols: object, values: object, shape: tuple[int, int]) -> Triplets:
        """The matrix of these entries; repeated positions are added up."""
        r = np.asarray(rows, dtype=np.int64).reshape(-1)
        c = np.asarray(cols, dtype=np.int64).reshape(-1)
        v = np.asarray(values, dtype=np.float64).reshape(-1)
        order = np.lexsort((c, r))
        r, c, v = r[order], c[order], v[order]
        if len(r):
            start = np.ones(len(r), dtype=bool)
            start[1:] = (r[1:] != r[:-1]) | (c[1:] != c[:-1])
            if not start.all():
                at = np.flatnonzero(start)
                v = np.add.reduceat(v, at)
                r, c = r[at], c[at]
        return Triplets(r, c, v, shape)

    def __matmul__(self, x: FloatArray) -> FloatArray:
        out = np.zeros(self.shape[0])
        np.add.at(out, self.rows, self.values * np.asarray(x, dtype=np.float64)[self.cols])
        return out

    def toarray(self) -> FloatArray:
        """The dense matrix."""
        dense = np.zeros(self.shape)
        dense[self.rows, self.cols] = self.values
        return dense


@dataclass(frozen=True, slots=True)
class CscMatrix:
    """Compressed sparse columns, row indices sorted within each column."""

    data: FloatArray
    indices: IntArray
    indptr: IntArray
    shape: tuple[int, int]

    @property
    def nnz(self) -> int:
        """Number of stored entries."""
        return len(self.data)

    @property
    def has_canonical_format(self) -> bool:
        """Sorted indices, no duplicates (Clarabel asks): true by construction."""
        return True


def stacked_csc(blocks: list[tuple[int, Triplets]], shape: tuple[int, int]) -> CscMatrix:
    """The CSC matrix holding each block's entries shifted down by its row offset."""
    rows = np.concatenate([b.rows + offset for offset, b in blocks] or [np.zeros(0, np.int64)])
    cols = np.concatenate([b.cols for _, b in blocks] or [np.zeros(0, np.int64)])
    values = np.concatenate([b.values for _, b in blocks] or [np.zeros(0)])
    order = np.lexsort((rows, cols))
    indptr = np.zeros(shape[1] + 1, dtype=np.int64)
    np.cumsum(np.bincount(cols, minlength=shape[1]), out=indptr[1:])
    return CscMatrix(values[order], rows[order], indptr, shape)
