"""The verifier's one evaluator: a formula's value on the pieces of a trace, however it ends.

``evaluate(formula, atoms, size, ending)`` gives the interval value ``(lo, hi)`` of ``formula``
at each of ``size`` pieces (see :mod:`tlmpc.verify.evaluate` for interval values: two-valued
truth, three-valued truth and robustness are all read off them).  ``ending`` says what follows
the last piece:

* an ``int`` k: the pieces from k on repeat forever (a lasso; k is a point piece);
* ``"stay"``: the robot stays at its last point, whose value holds forever after;
* ``"open"``: the log ends; every proposition is unknown afterwards (LTL3, sound).

Untimed formulas are evaluated by the lasso recursion of :class:`IntervalEvaluator` on the
pieces themselves (for ``open``, after them comes a future position where every atom is
unknown, looping on itself; for ``stay``, the last piece loops on itself).

Formulas with time bounds (``F[a,b]``, ``G[a,b]``, ``U[a,b]``) need the pieces' times
(:class:`Timing`) and are evaluated in dense time (:mod:`tlmpc.verify.dense`): every
sub-formula becomes a piecewise-constant signal on its own grid of instants, and the values
returned here are that signal read on the trace's pieces (a piece a bound cuts into parts gets
the hull of their values; the first piece, an instant, is always read exactly).
"""

from __future__ import annotations

from collections import ChainMap
from collections.abc import Callable, Iterator, MutableMapping
from contextlib import contextmanager

import numpy as np
import numpy.typing as npt

from tlmpc.ltl.ast import Formula, bounded_operators
from tlmpc.verify.dense import DenseSemantics, PieceEnding, Timing
from tlmpc.verify.evaluate import UNKNOWN, IntervalEvaluator, Value

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


class Semantics:
    """Values of formulas on the pieces of one trace, memoised per formula."""

    def __init__(
        self,
        atoms: Callable[[str], Value],
        size: int,
        ending: PieceEnding,
        *,
        is_point: BoolArray | None = None,
        timing: Timing | None = None,
    ) -> None:
        if size < 1:
            raise ValueError("a trace has at least one piece")
        if isinstance(ending, int) and not 0 <= ending < size:
            raise ValueError(f"loop {ending} outside 0..{size - 1}")
        self.atoms = atoms
        self.size = size
        self.ending = ending
        self.is_point = is_point
        self.timing = timing
        self._untimed = self._lasso()
        self._dense: DenseSemantics | None = None
        self.cache: MutableMapping[Formula, Value] = {}

    def _lasso(self) -> IntervalEvaluator:
        atoms, size, ending, is_point = self.atoms, self.size, self.ending, self.is_point
        if ending == "open":

            def padded(name: str) -> Value:
                lo, hi = atoms(name)
                return np.append(lo, UNKNOWN[0]), np.append(hi, UNKNOWN[1])

            points = None if is_point is None else np.append(is_point, False)
            return IntervalEvaluator(padded, size + 1, size, points)
        loop = size - 1 if ending == "stay" else ending
        return IntervalEvaluator(atoms, size, loop, is_point)

    def dense(self) -> DenseSemantics:
        """The dense-time evaluator of this trace (time-bounded formulas)."""
        if self._dense is None:
            if self.timing is None:
                raise ValueError("a formula with time bounds needs the pieces' times")
            self._dense = DenseSemantics(self.atoms, self.size, self.ending, self.timing)
        return self._dense

    @contextmanager
    def scratch(self) -> Iterator[None]:
        """Values computed in the block are forgotten after it (those known before are kept,
        and used): a search that evaluates many variants of one formula, each a new key of
        the memo, then holds one variant's signals at a time instead of all of them."""
        dense = self.dense() if self.timing is not None else None
        kept, dense_kept = self.cache, None if dense is None else dense.cache
        self.cache = ChainMap({}, kept)
        if dense is not None and dense_kept is not None:
            dense.cache = ChainMap({}, dense_kept)
        try:
            yield
        finally:
            self.cache = kept
            if dense is not None and dense_kept is not None:
                dense.cache = dense_kept

    def __call__(self, formula: Formula) -> Value:
        """``(lo, hi)`` of ``formula`` at each piece."""
        cached = self.cache.get(formula)
        if cached is None:
            if bounded_operators(formula):
                cached = self.dense().on_pieces(formula)
            else:
                lo, hi = self._untimed(formula)
                cached = (lo[: self.size], hi[: self.size])
            self.cache[formula] = cached
        return cached

    def at_start(self, formula: Formula) -> tuple[float, float]:
        """``(lo, hi)`` of ``formula`` at the first instant."""
        lo, hi = self(formula)
        return float(lo[0]), float(hi[0])


def evaluate(
    formula: Formula,
    atoms: Callable[[str], Value],
    size: int,
    ending: PieceEnding,
    *,
    is_point: BoolArray | None = None,
    timing: Timing | None = None,
) -> Value:
    """``(lo, hi)`` of ``formula`` at each of ``size`` pieces followed by ``ending``.

    ``is_point`` marks point pieces under the closed convention (None: every piece has a first
    instant); ``timing`` is needed for time-bounded operators.
    """
    return Semantics(atoms, size, ending, is_point=is_point, timing=timing)(formula)


def three_valued(value: Value) -> npt.NDArray[np.int8]:
    """+1 where ``value`` is surely true, -1 surely false, 0 unknown."""
    lo, hi = value
    result = np.zeros(len(lo), dtype=np.int8)
    result[lo > 0] = 1
    result[hi < 0] = -1
    return result


__all__ = ["PieceEnding", "Semantics", "Timing", "evaluate", "three_valued"]
