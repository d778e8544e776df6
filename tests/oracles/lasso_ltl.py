"""A definition-level LTL evaluator on lasso words u·v^ω, independent of tlmpc's code.

Positions 0..n-1, the word repeats positions loop..n-1 forever.  Until is checked by its
definition: walk forward from i over one full turn of the loop looking for a witness.
Used as the oracle for the translator, the NNF rewrite and the verifier.
"""

from __future__ import annotations

from collections.abc import Sequence

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

Word = Sequence[frozenset[str]]


def _forward(i: int, n: int, loop: int) -> list[int]:
    """Positions i, i+1, ... until every position reachable from i was seen once."""
    seen: list[int] = []
    position = i
    visited: set[int] = set()
    while position not in visited:
        visited.add(position)
        seen.append(position)
        position = position + 1 if position + 1 < n else loop
    return seen


def holds(f: Formula, word: Word, loop: int, i: int = 0) -> bool:
    """Truth of ``f`` at position ``i`` of the lasso ``word`` (loop start ``loop``)."""
    n = len(word)
    if isinstance(f, Const):
        return f.value
    if isinstance(f, Prop):
        return f.name in word[i]
    if isinstance(f, Not):
        return not holds(f.arg, word, loop, i)
    if isinstance(f, And):
        return all(holds(a, word, loop, i) for a in f.args)
    if isinstance(f, Or):
        return any(holds(a, word, loop, i) for a in f.args)
    if isinstance(f, Implies):
        return not holds(f.left, word, loop, i) or holds(f.right, word, loop, i)
    if isinstance(f, Equiv):
        return holds(f.left, word, loop, i) == holds(f.right, word, loop, i)
    if isinstance(f, Until):
        for j in _forward(i, n, loop):
            if holds(f.right, word, loop, j):
                return True
            if not holds(f.left, word, loop, j):
                return False
        return False
    if isinstance(f, Eventually):
        return any(holds(f.arg, word, loop, j) for j in _forward(i, n, loop))
    if isinstance(f, Globally):
        return all(holds(f.arg, word, loop, j) for j in _forward(i, n, loop))
    if isinstance(f, Release):  # b holds until and including a, or forever
        for j in _forward(i, n, loop):
            if not holds(f.right, word, loop, j):
                return False
            if holds(f.left, word, loop, j):
                return True
        return True
    if isinstance(f, WeakUntil):
        for j in _forward(i, n, loop):
            if holds(f.right, word, loop, j):
                return True
            if not holds(f.left, word, loop, j):
                return False
        return True
    if isinstance(f, StrongRelease):
        for j in _forward(i, n, loop):
            if not holds(f.right, word, loop, j):
                return False
            if holds(f.left, word, loop, j):
                return True
        return False
    raise TypeError(f)
