"""The continuous-time definition of Next-free LTL on point/open piece words (closed convention).

Every open piece contributes two instants, "just after its start" and "later"; ``a U b`` at
instant t holds iff some instant s >= t has b with a at every instant in [t, s), and s may be
the "just after" instant of an open piece only when s = t (there is no first instant after a
point, so any later witness inside an open piece leaves part of the piece in [t, s)).  R, W,
M, F and G by their definitions.  Independent of tlmpc's verifier and planner.
"""

from __future__ import annotations

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

Word = list[frozenset[str]]


def _instants(word: Word, is_point: list[bool], loop: int) -> tuple[Word, list[bool], int]:
    """Instants of the pieces: open pieces twice, the first copy marked "just after"."""
    letters_: Word = []
    just_after: list[bool] = []
    new_loop = 0
    for index, (letter, point) in enumerate(zip(word, is_point, strict=True)):
        if index == loop:
            new_loop = len(letters_)
        letters_.extend([letter] if point else [letter, letter])
        just_after.extend([False] if point else [True, False])
    return letters_, just_after, new_loop


def _forward(i: int, n: int, loop: int) -> list[int]:
    seen, position, visited = [], i, set()
    while position not in visited:
        visited.add(position)
        seen.append(position)
        position = position + 1 if position + 1 < n else loop
    return seen


def continuous_holds(
    f: Formula, instants: Word, just_after: list[bool], loop: int, i: int = 0
) -> bool:
    """The continuous-time definition at instant ``i`` (R, W, M, F, G by their definitions)."""

    def at(g: Formula, j: int) -> bool:
        return continuous_holds(g, instants, just_after, loop, j)

    n = len(instants)
    if isinstance(f, Const):
        return f.value
    if isinstance(f, Prop):
        return f.name in instants[i]
    if isinstance(f, Not):
        return not at(f.arg, i)
    if isinstance(f, And):
        return all(at(g, i) for g in f.args)
    if isinstance(f, Or):
        return any(at(g, i) for g in f.args)
    if isinstance(f, Implies):
        return not at(f.left, i) or at(f.right, i)
    if isinstance(f, Equiv):
        return at(f.left, i) == at(f.right, i)
    if isinstance(f, Until):
        path = _forward(i, n, loop)
        for index, j in enumerate(path):
            witness_allowed = j == i or not just_after[j]
            if witness_allowed and at(f.right, j) and all(at(f.left, k) for k in path[:index]):
                return True
        return False
    if isinstance(f, Eventually):
        return at(Until(Const(True), f.arg), i)
    if isinstance(f, Globally):
        return not at(Eventually(Not(f.arg)), i)
    if isinstance(f, Release):
        return not at(Until(Not(f.left), Not(f.right)), i)
    if isinstance(f, WeakUntil):
        return at(Until(f.left, f.right), i) or at(Globally(f.left), i)
    if isinstance(f, StrongRelease):
        return at(Until(f.right, And((f.left, f.right))), i)
    raise TypeError(f)


def closed_holds(formula: Formula, word: Word, is_point: list[bool], loop: int, k: int) -> bool:
    """The definition at the first instant of piece ``k``."""
    instants, just_after, new_loop = _instants(word, is_point, loop)
    position = len(_instants(word[:k], is_point[:k], 0)[0])
    return continuous_holds(formula, instants, just_after, new_loop, position)
