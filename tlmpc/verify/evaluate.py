"""Direct LTL evaluation on a lasso of positions, with interval values: the recursion that
:mod:`tlmpc.verify.semantics` runs for every question the verifier asks (how a trace's end
becomes a lasso is decided there, once).  A value is a pair of arrays ``(lo, hi)`` over the
positions: the formula's value is known to lie in ``[lo, hi]``.

* Two-valued truth: atoms are +1 (in the region) or -1, ``lo == hi``.
* Three-valued truth (a log that may go on): an unknown atom is ``(-1, +1)``; a value with
  ``lo > 0`` is true for every continuation, ``hi < 0`` false for every one, else unknown.
* Robustness: atoms are signed distances (``lo == hi``), or tubes ``(d - e, d + e)``.

Negation maps ``[lo, hi]`` to ``[-hi, -lo]``; ``&``/``|`` take min/max of both ends.
Positions form a lasso: the successor of the last position is ``loop``.  Until is the least
fixpoint of ``U_k = max(b_k, min(a_k, [a_{k+1} if k is a point piece], U_{k+1}))`` (the bracket
only under the closed convention: an open piece has no first instant), computed with two
backward passes around the loop.  The other operators are their definitions: ``F b = true U b``,
``G a = !F !a``, ``a R b = !(!a U !b)``, ``a W b = (a U b) | G a``, ``a M b = b U (a & b)``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import assert_never

import numpy as np
import numpy.typing as npt

from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedGlobally,
    BoundedUntil,
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

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]
Value = tuple[FloatArray, FloatArray]

#: The value of an atom that nothing is known about.
UNKNOWN = (-np.inf, np.inf)


class IntervalEvaluator:
    """Interval values of formulas at every position of a lasso, memoised per formula.

    ``atoms(name)`` gives a proposition's ``(lo, hi)`` arrays; ``is_point`` marks point pieces
    under the closed convention (None: every position has a first instant).
    """

    def __init__(
        self,
        atoms: Callable[[str], Value],
        size: int,
        loop: int,
        is_point: BoolArray | None = None,
    ) -> None:
        if not 0 <= loop < size:
            raise ValueError(f"loop {loop} outside 0..{size - 1}")
        self.atoms = atoms
        self.size = size
        self.loop = loop
        self.is_point = is_point
        self.cache: dict[Formula, Value] = {}

    def __call__(self, formula: Formula) -> Value:
        cached = self.cache.get(formula)
        if cached is None:
            cached = self._eval(formula)
            self.cache[formula] = cached
        return cached

    # -- the one recursion ------------------------------------------------------------------

    def _until_side(self, a: FloatArray, b: FloatArray) -> FloatArray:
        size, loop = self.size, self.loop
        point = self.is_point.tolist() if self.is_point is not None else None
        a_list, b_list = a.tolist(), b.tolist()
        values = [-np.inf] * size
        # A self-loop on the last position needs one pass (its fixpoint is b there).
        passes = 1 if loop == size - 1 else 2
        # Plain comparisons instead of min/max: this loop is the verifier's hot spot.
        for _ in range(passes):
            following = values[loop]
            for k in range(size - 1, -1, -1):
                step = a_list[k]
                if following < step:
                    step = following
                if point is not None and point[k]:
                    after = a_list[k + 1] if k + 1 < size else a_list[loop]
                    if after < step:
                        step = after
                here = b_list[k]
                following = here if here > step else step
                values[k] = following
        return np.asarray(values, dtype=np.float64)

    def until(self, a: Value, b: Value) -> Value:
        """``a U b`` from the values of ``a`` and ``b``."""
        lo = self._until_side(a[0], b[0])
        if a[0] is a[1] and b[0] is b[1]:
            return lo, lo
        return lo, self._until_side(a[1], b[1])

    def _eventually_side(self, b: FloatArray) -> FloatArray:
        # The running maximum from the end, written backwards into its place (no reversed copy).
        result = np.empty(len(b), dtype=b.dtype)
        np.maximum.accumulate(b[::-1], out=result[::-1])
        result[self.loop :] = np.max(b[self.loop :])
        return np.asarray(result, dtype=np.float64)

    def eventually(self, b: Value) -> Value:
        """``F b`` (``true U b``: no point rule applies since ``true`` holds everywhere)."""
        lo = self._eventually_side(b[0])
        return (lo, lo) if b[0] is b[1] else (lo, self._eventually_side(b[1]))

    # -- connectives -------------------------------------------------------------------------

    @staticmethod
    def negate(a: Value) -> Value:
        """``!a``."""
        if a[0] is a[1]:
            neg = -a[0]
            return neg, neg
        return -a[1], -a[0]

    @staticmethod
    def meet(values: list[Value]) -> Value:
        """``&``: the minimum of both ends."""
        lo = np.minimum.reduce([v[0] for v in values])
        if all(v[0] is v[1] for v in values):
            return lo, lo
        return lo, np.minimum.reduce([v[1] for v in values])

    @staticmethod
    def join(values: list[Value]) -> Value:
        """``|``: the maximum of both ends."""
        lo = np.maximum.reduce([v[0] for v in values])
        if all(v[0] is v[1] for v in values):
            return lo, lo
        return lo, np.maximum.reduce([v[1] for v in values])

    def _eval(self, f: Formula) -> Value:
        match f:
            case Const(value):
                filled = np.full(self.size, np.inf if value else -np.inf)
                return filled, filled
            case Prop(name):
                return self.atoms(name)
            case Not(arg):
                return self.negate(self(arg))
            case And(args):
                return self.meet([self(a) for a in args])
            case Or(args):
                return self.join([self(a) for a in args])
            case Implies(left, right):
                return self.join([self.negate(self(left)), self(right)])
            case Equiv(left, right):
                left_value, right_value = self(left), self(right)
                return self.meet(
                    [
                        self.join([self.negate(left_value), right_value]),
                        self.join([left_value, self.negate(right_value)]),
                    ]
                )
            case Until(left, right):
                return self.until(self(left), self(right))
            case Eventually(arg):
                return self.eventually(self(arg))
            case Globally(arg):
                return self.negate(self.eventually(self.negate(self(arg))))
            case Release(left, right):
                return self.negate(self.until(self.negate(self(left)), self.negate(self(right))))
            case WeakUntil(left, right):
                left_value = self(left)
                always = self.negate(self.eventually(self.negate(left_value)))
                return self.join([self.until(left_value, self(right)), always])
            case StrongRelease(left, right):
                right_value = self(right)
                return self.until(right_value, self.meet([self(left), right_value]))
            case BoundedEventually() | BoundedGlobally() | BoundedUntil():
                raise ValueError(
                    "a time bound needs the pieces' times: evaluate it with "
                    "tlmpc.verify.semantics.evaluate"
                )
            case _:
                assert_never(f)


def truth_atoms(
    labels: BoolArray, names: list[str], unknown: BoolArray | None = None
) -> Callable[[str], Value]:
    """Atoms from a label matrix (positions × regions): +1 in, -1 out, (-1, +1) unknown."""
    column = {name: i for i, name in enumerate(names)}

    def atom(name: str) -> Value:
        index = column[name]
        known = np.where(labels[:, index], 1.0, -1.0)
        if unknown is None or not unknown[:, index].any():
            return known, known
        lo = np.where(unknown[:, index], -1.0, known)
        hi = np.where(unknown[:, index], 1.0, known)
        return lo, hi

    return atom
