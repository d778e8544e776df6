"""Formula progression: the task's obligation after each piece of a live trajectory.

The offline verifier evaluates the task on the whole word of pieces followed by an unknown
future (docs/verify.md).  A live monitor cannot keep the word, so it keeps the *residue*: the
formula the rest of the word must satisfy, rewritten after every piece by the same recursion
the offline evaluator computes backwards,

    a U b  after a piece  =  b' | (a' & [a, after a point piece, closed convention] & (a U b))

where ``x'`` is ``x`` after the piece (its atoms replaced by the piece's labels).  The other
operators are the evaluator's own definitions (``F b = true U b``, ``G a = !F !a``, ``a R b =
!(!a U !b)``, ``a W b = (a U b) | G a``, ``a M b = b U (a & b)``); negations are pushed to atoms
and untils, conjunctions and disjunctions flattened, constants folded and duplicates dropped,
so the residue stays a small combination of the task's subformulas however long the log.
The three-valued value of a residue on the last few pieces and the unknown future after them
is :func:`value`, which is the offline evaluator's recursion on that short word (truth values
are Kleene's: -1 false, 0 unknown, +1 true).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeAlias

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

#: A residue: ``("T",)``, ``("F",)``, ``("p", name)``, ``("!", residue)`` (over an atom or an
#: until only), ``("&", frozenset)``, ``("|", frozenset)``, ``("U", left, right)``.
Residue: TypeAlias = tuple[object, ...]

TRUE: Residue = ("T",)
FALSE: Residue = ("F",)


def negate(r: Residue) -> Residue:
    """``!r`` with the negation pushed inward (De Morgan holds in Kleene's logic)."""
    kind = r[0]
    if kind == "T":
        return FALSE
    if kind == "F":
        return TRUE
    if kind == "!":
        inner = r[1]
        assert isinstance(inner, tuple)
        return inner
    if kind in ("&", "|"):
        items = r[1]
        assert isinstance(items, frozenset)
        return join([negate(i) for i in items]) if kind == "&" else meet([negate(i) for i in items])
    return ("!", r)


def _gather(kind: str, items: Sequence[Residue]) -> set[Residue]:
    found: set[Residue] = set()
    for item in items:
        if item[0] == kind:
            inner = item[1]
            assert isinstance(inner, frozenset)
            found |= inner
        else:
            found.add(item)
    return found


def meet(items: Sequence[Residue]) -> Residue:
    """``&`` of the items, flattened and folded."""
    found = _gather("&", items)
    if FALSE in found:
        return FALSE
    found.discard(TRUE)
    if not found:
        return TRUE
    if len(found) == 1:
        return found.pop()
    return ("&", frozenset(found))


def join(items: Sequence[Residue]) -> Residue:
    """``|`` of the items, flattened and folded."""
    found = _gather("|", items)
    if TRUE in found:
        return TRUE
    found.discard(FALSE)
    if not found:
        return FALSE
    if len(found) == 1:
        return found.pop()
    return ("|", frozenset(found))


def residue(formula: Formula) -> Residue:
    """The formula in the residue's core (the evaluator's definitions of the operators)."""
    match formula:
        case Const(value):
            return TRUE if value else FALSE
        case Prop(name):
            return ("p", name)
        case Not(arg):
            return negate(residue(arg))
        case And(args):
            return meet([residue(a) for a in args])
        case Or(args):
            return join([residue(a) for a in args])
        case Implies(left, right):
            return join([negate(residue(left)), residue(right)])
        case Equiv(left, right):
            a, b = residue(left), residue(right)
            return meet([join([negate(a), b]), join([a, negate(b)])])
        case Until(left, right):
            return ("U", residue(left), residue(right))
        case Eventually(arg):
            return ("U", TRUE, residue(arg))
        case Globally(arg):
            return negate(("U", TRUE, negate(residue(arg))))
        case Release(left, right):
            return negate(("U", negate(residue(left)), negate(residue(right))))
        case WeakUntil(left, right):
            a = residue(left)
            return join([("U", a, residue(right)), negate(("U", TRUE, negate(a)))])
        case StrongRelease(left, right):
            b = residue(right)
            return ("U", b, meet([residue(left), b]))
        case _:
            # time bounds are refused before any residue is made (the monitor's F010)
            raise ValueError(f"no residue for a time-bounded operator: {formula}")


@dataclass(frozen=True, slots=True)
class Piece:
    """One piece of the trajectory: the regions it is in, those unknown, and whether it is a
    point piece under the closed convention (only then does the point rule apply)."""

    inside: frozenset[str]
    unknown: frozenset[str] = frozenset()
    point_rule: bool = False


def progress(r: Residue, piece: Piece) -> Residue:
    """The residue after ``piece`` (whose labels are all known)."""
    kind = r[0]
    if kind in ("T", "F"):
        return r
    if kind == "p":
        return TRUE if r[1] in piece.inside else FALSE
    if kind == "!":
        inner = r[1]
        assert isinstance(inner, tuple)
        return negate(progress(inner, piece))
    if kind in ("&", "|"):
        items = r[1]
        assert isinstance(items, frozenset)
        done = [progress(i, piece) for i in items]
        return meet(done) if kind == "&" else join(done)
    left, right = r[1], r[2]
    assert isinstance(left, tuple)
    assert isinstance(right, tuple)
    stay = [progress(left, piece), r]
    if piece.point_rule:
        stay.append(left)
    return join([progress(right, piece), meet(stay)])


def value(r: Residue, tail: Sequence[Piece]) -> int:
    """The Kleene value (-1, 0, +1) of ``r`` on ``tail`` followed by the unknown future."""
    memo: dict[tuple[int, Residue], int] = {}

    def at(f: Residue, k: int) -> int:
        key = (k, f)
        if key in memo:
            return memo[key]
        kind = f[0]
        result: int
        if kind == "T":
            result = 1
        elif kind == "F":
            result = -1
        elif kind == "p":
            if k == len(tail) or f[1] in tail[k].unknown:
                result = 0
            else:
                result = 1 if f[1] in tail[k].inside else -1
        elif kind == "!":
            inner = f[1]
            assert isinstance(inner, tuple)
            result = -at(inner, k)
        elif kind in ("&", "|"):
            items = f[1]
            assert isinstance(items, frozenset)
            values = [at(i, k) for i in items]
            result = min(values) if kind == "&" else max(values)
        else:
            left, right = f[1], f[2]
            assert isinstance(left, tuple)
            assert isinstance(right, tuple)
            if k == len(tail):
                result = at(right, k)  # the future loops on itself: the least fixpoint is b
            else:
                stay = min(at(left, k), at(f, k + 1))
                if tail[k].point_rule:
                    stay = min(stay, at(left, k + 1))
                result = max(at(right, k), stay)
        memo[key] = result
        return result

    return at(r, 0)
