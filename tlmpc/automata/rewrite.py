"""Implication-based rewriting of the translator's formulas (Somenzi–Bloem; the rules Spot's
``tl_simplifier`` applies with syntactic implication checks).

Bottom-up, every node is rebuilt from its rewritten operands, then the rules below apply, each
decided by the sound syntactic implication check :func:`tlmpc.automata.terms.implies` (never
by a translation, so the pass is cheap enough to run on every formula):

==================  ====================  ======================
node                becomes               when
==================  ====================  ======================
``a | b``           ``b``                 a ⇒ b
``a | b``           ``true``              ¬a ⇒ b
``a & b``           ``a``                 a ⇒ b
``a & b``           ``false``             a ⇒ ¬b
``a U b``           ``b``                 a ⇒ b
``a U b``           ``F b``               ¬a ⇒ b
``a W b``           ``b``                 a ⇒ b
``a W b``           ``true``              ¬a ⇒ b
``a R b``           ``b``                 b ⇒ a
``a R b``           ``G b``               b ⇒ ¬a
``a M b``           ``b``                 b ⇒ a
``a M b``           ``false``             b ⇒ ¬a
``a U (b U c)``     ``b U c``             a ⇒ b
``a W (b W c)``     ``b W c``             a ⇒ b
``a R (b R c)``     ``b R c``             b ⇒ a
``a M (b M c)``     ``b M c``             b ⇒ a
==================  ====================  ======================

Why they hold: for ``a U b`` with a ⇒ b, wherever ``a`` holds so does ``b``, so the until is
fulfilled at once or never needed ``a``; with ¬a ⇒ b every position before the first ``b`` has
``a``.  The ``R``/``M`` rules are the duals (``¬(a U b) = ¬a R ¬b``, ``¬(a W b) = ¬a M ¬b``).
"""

from __future__ import annotations

import functools

from tlmpc.automata.terms import (
    FALSE,
    TRUE,
    T,
    implies,
    make_and,
    make_binary,
    make_f,
    make_g,
    make_or,
)

#: Nodes with more operands are rebuilt without the pairwise checks (they are quadratic).
MAX_OPERANDS = 12


def negate(f: T) -> T:
    """The negation normal form of ``!f`` (rebuilt through the simplifying constructors)."""
    kind = f[0]
    if kind == "t":
        return FALSE
    if kind == "f":
        return TRUE
    if kind == "p":
        return ("n", f[1])
    if kind == "n":
        return ("p", f[1])
    if kind == "&":
        return make_or([negate(a) for a in f[1]])
    if kind == "|":
        return make_and([negate(a) for a in f[1]])
    if kind == "F":
        return make_g(negate(f[1]))
    if kind == "G":
        return make_f(negate(f[1]))
    dual = {"U": "R", "R": "U", "W": "M", "M": "W"}[kind]
    return make_binary(dual, negate(f[1]), negate(f[2]))


@functools.lru_cache(maxsize=1 << 14)
def rewrite(f: T) -> T:
    """``f`` with the implication rules of the module docstring applied at every node."""
    kind = f[0]
    if kind in ("t", "f", "p", "n"):
        return f
    if kind in ("&", "|"):
        args = [rewrite(a) for a in f[1]]
        return _junction(kind, args)
    if kind == "F":
        return make_f(rewrite(f[1]))
    if kind == "G":
        return make_g(rewrite(f[1]))
    return _binary(kind, rewrite(f[1]), rewrite(f[2]))


def _junction(kind: str, args: list[T]) -> T:
    built = make_and(args) if kind == "&" else make_or(args)
    if built[0] != kind or len(built[1]) > MAX_OPERANDS:
        return built
    items = list(built[1])
    conjunction = kind == "&"
    for index, item in enumerate(items):
        for other in items[index + 1 :]:
            if conjunction and (implies(item, negate(other)) or implies(other, negate(item))):
                return FALSE
            if not conjunction and (implies(negate(item), other) or implies(negate(other), item)):
                return TRUE
    # Drop, one at a time, an operand that another remaining one makes redundant (so of two
    # equivalent operands one stays).
    kept = list(items)
    for item in items:
        if any(
            other is not item and (implies(other, item) if conjunction else implies(item, other))
            for other in kept
        ):
            kept.remove(item)
    if len(kept) == len(items):
        return built
    return make_and(kept) if conjunction else make_or(kept)


def _binary(kind: str, a: T, b: T) -> T:
    if kind in ("U", "W"):
        if implies(a, b):
            return b
        if implies(negate(a), b):
            return make_f(b) if kind == "U" else TRUE
        if b[0] == kind and implies(a, b[1]):
            return b
    else:  # R, M
        if implies(b, a):
            return b
        if implies(b, negate(a)):
            return make_g(b) if kind == "R" else FALSE
        if b[0] == kind and implies(b[1], a):
            return b
    return make_binary(kind, a, b)
