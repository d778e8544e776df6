"""Direct LTL evaluation on a lasso of pieces (the verifier's own semantics).

Positions are pieces; the successor of the last piece is the loop start (for a finite
trace: the last piece itself, which lasts forever).  Until is the least fixpoint of
U_k = b_k | (a_k & [a_{k+1} if k is a point piece under the closed convention] & U_{k+1}),
computed with two backward passes around the loop.  Other operators reduce to it:
F b = true U b, G a = !F !a, a R b = !(!a U !b), a W b = (a U b) | G a, a M b = b U (a & b).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from tlmpc.ltl.ast import (
    And,
    Const,
    Equiv,
    Eventually,
    Formula,
    Globally,
    Implies,
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
)

BoolArray = npt.NDArray[np.bool_]


class LassoEvaluator:
    """Truth of formulas at every piece of ``labels`` (pieces × regions), memoised."""

    def __init__(
        self,
        labels: BoolArray,
        names: list[str],
        loop_start: int,
        is_point: BoolArray | None = None,
    ) -> None:
        self.labels = labels
        self.column = {name: i for i, name in enumerate(names)}
        self.size = labels.shape[0]
        self.loop_start = loop_start
        self.is_point = is_point  # None: half-open pieces (right-continuous convention)
        self.cache: dict[Formula, BoolArray] = {}

    def successor(self, k: int) -> int:
        """The piece after ``k``."""
        return k + 1 if k + 1 < self.size else self.loop_start

    def __call__(self, formula: Formula) -> BoolArray:
        cached = self.cache.get(formula)
        if cached is None:
            cached = self._eval(formula)
            self.cache[formula] = cached
        return cached

    def _until(self, a: BoolArray, b: BoolArray) -> BoolArray:
        result = np.zeros(self.size, dtype=bool)
        needs_next_a = self.is_point if self.is_point is not None else np.zeros(self.size, bool)
        a_list, b_list, point_list = a.tolist(), b.tolist(), needs_next_a.tolist()
        values = result.tolist()
        for _ in range(2):  # two passes reach the least fixpoint around the loop
            for k in range(self.size - 1, -1, -1):
                nxt = k + 1 if k + 1 < self.size else self.loop_start
                step = a_list[k] and values[nxt] and (not point_list[k] or a_list[nxt])
                values[k] = b_list[k] or step
        return np.array(values, dtype=bool)

    def _eval(self, f: Formula) -> BoolArray:
        if isinstance(f, Const):
            return np.full(self.size, f.value)
        if isinstance(f, Prop):
            return self.labels[:, self.column[f.name]].copy()
        if isinstance(f, Not):
            return ~self(f.arg)
        if isinstance(f, And):
            result = np.ones(self.size, dtype=bool)
            for arg in f.args:
                result &= self(arg)
            return result
        if isinstance(f, Or):
            result = np.zeros(self.size, dtype=bool)
            for arg in f.args:
                result |= self(arg)
            return result
        if isinstance(f, Implies):
            return ~self(f.left) | self(f.right)
        if isinstance(f, Equiv):
            equal: BoolArray = self(f.left) == self(f.right)
            return equal
        if isinstance(f, Until):
            return self._until(self(f.left), self(f.right))
        if isinstance(f, Eventually):
            return self._until(np.ones(self.size, dtype=bool), self(f.arg))
        if isinstance(f, Globally):
            return ~self._until(np.ones(self.size, dtype=bool), ~self(f.arg))
        if isinstance(f, Release):
            return ~self._until(~self(f.left), ~self(f.right))
        if isinstance(f, WeakUntil):
            left = self(f.left)
            always = ~self._until(np.ones(self.size, dtype=bool), ~left)
            return self._until(left, self(f.right)) | always
        if isinstance(f, StrongRelease):
            right = self(f.right)
            return self._until(right, self(f.left) & right)
        raise TypeError(f"not an LTL node: {f!r}")


def evaluate(
    formula: Formula,
    labels: BoolArray,
    names: list[str],
    loop_start: int | None,
    is_point: BoolArray | None = None,
    cache: Mapping[Formula, BoolArray] | None = None,
) -> bool:
    """Truth of ``formula`` at the first piece (finite trace when ``loop_start`` is None)."""
    start = labels.shape[0] - 1 if loop_start is None else loop_start
    evaluator = LassoEvaluator(labels, names, start, is_point)
    if cache:
        evaluator.cache.update(cache)
    return bool(evaluator(formula)[0])
