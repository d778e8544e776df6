"""Rewrites of LTL formulas: negation normal form, substitution, syntactic classes.

NNF keeps ``W``/``M``/``R`` as native operators (expanding ``W`` duplicates a subformula)
and uses the dualities ``!(a U b) = !a R !b``, ``!(a R b) = !a U !b``,
``!(a W b) = !a M !b``, ``!(a M b) = !a W !b``, ``!F a = G !a``, ``!G a = F !a``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from tlmpc.ltl.ast import (
    FALSE,
    TRUE,
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
    conjoin,
    disjoin,
)

_DUAL: dict[type, Callable[[Formula, Formula], Formula]] = {
    Until: lambda a, b: Release(a, b),
    Release: lambda a, b: Until(a, b),
    WeakUntil: lambda a, b: StrongRelease(a, b),
    StrongRelease: lambda a, b: WeakUntil(a, b),
}
_SAME: dict[type, Callable[[Formula, Formula], Formula]] = {
    Until: lambda a, b: Until(a, b),
    Release: lambda a, b: Release(a, b),
    WeakUntil: lambda a, b: WeakUntil(a, b),
    StrongRelease: lambda a, b: StrongRelease(a, b),
}


def nnf(formula: Formula, negate: bool = False) -> Formula:
    """Negation normal form of ``formula`` (of its negation when ``negate``).

    The result has no ``->``/``<->`` and negations only directly above propositions.
    """
    f = formula
    if isinstance(f, Const):
        return Const(f.value != negate)
    if isinstance(f, Prop):
        return Not(f) if negate else Prop(f.name)
    if isinstance(f, Not):
        return nnf(f.arg, not negate)
    if isinstance(f, And | Or):
        parts = [nnf(a, negate) for a in f.args]
        use_and = isinstance(f, And) != negate
        return conjoin(parts) if use_and else disjoin(parts)
    if isinstance(f, Implies):
        # a -> b  ==  !a | b ;  !(a -> b)  ==  a & !b
        if negate:
            return conjoin([nnf(f.left), nnf(f.right, True)])
        return disjoin([nnf(f.left, True), nnf(f.right)])
    if isinstance(f, Equiv):
        # a <-> b == (a & b) | (!a & !b);  !(a <-> b) == (a & !b) | (!a & b)
        a, na = nnf(f.left), nnf(f.left, True)
        b, nb = nnf(f.right), nnf(f.right, True)
        if negate:
            return disjoin([conjoin([a, nb]), conjoin([na, b])])
        return disjoin([conjoin([a, b]), conjoin([na, nb])])
    if isinstance(f, Eventually):
        return Globally(nnf(f.arg, True)) if negate else Eventually(nnf(f.arg))
    if isinstance(f, Globally):
        return Eventually(nnf(f.arg, True)) if negate else Globally(nnf(f.arg))
    if isinstance(f, Until | Release | WeakUntil | StrongRelease):
        build = _DUAL[type(f)] if negate else _SAME[type(f)]
        return build(nnf(f.left, negate), nnf(f.right, negate))
    raise TypeError(f"not an LTL node: {f!r}")


def substitute(formula: Formula, replace: Mapping[str, Formula]) -> Formula:
    """``formula`` with every proposition named in ``replace`` replaced (spans kept)."""
    f = formula
    if isinstance(f, Prop):
        return replace.get(f.name, f)
    if isinstance(f, Const):
        return f
    if isinstance(f, Not):
        return Not(substitute(f.arg, replace), span=f.span)
    if isinstance(f, And):
        return And(tuple(substitute(a, replace) for a in f.args), span=f.span)
    if isinstance(f, Or):
        return Or(tuple(substitute(a, replace) for a in f.args), span=f.span)
    if isinstance(f, Eventually):
        return Eventually(substitute(f.arg, replace), span=f.span)
    if isinstance(f, Globally):
        return Globally(substitute(f.arg, replace), span=f.span)
    if isinstance(f, Implies | Equiv | Until | Release | WeakUntil | StrongRelease):
        return type(f)(substitute(f.left, replace), substitute(f.right, replace), span=f.span)
    raise TypeError(f"not an LTL node: {f!r}")


def _only(formula: Formula, allowed: tuple[type, ...]) -> bool:
    for node in nnf(formula).walk():
        if isinstance(node, Const | Prop | Not | And | Or):
            continue
        if not isinstance(node, allowed):
            return False
    return True


def is_cosafe(formula: Formula) -> bool:
    """Syntactically co-safe: in NNF only ``& | U M F`` over literals.

    Every satisfying run of a co-safe formula has a finite good prefix, so a plan for it is
    a single path followed by any behaviour (tlmpc ends it in a stay).
    """
    return _only(formula, (Until, StrongRelease, Eventually))


def is_safety(formula: Formula) -> bool:
    """Syntactically safe: in NNF only ``& | R W G`` over literals."""
    return _only(formula, (Release, WeakUntil, Globally))


def _flatten(kind: type[And] | type[Or], parts: list[Formula]) -> list[Formula]:
    flat: list[Formula] = []
    for part in parts:
        flat.extend(part.args if isinstance(part, kind) else (part,))
    return flat


def simplify(formula: Formula) -> Formula:
    """Constant folding and flattening (meaning-preserving, cheap)."""
    f = formula
    if isinstance(f, Const | Prop):
        return f
    if isinstance(f, Not):
        arg = simplify(f.arg)
        if isinstance(arg, Const):
            return Const(not arg.value)
        if isinstance(arg, Not):
            return arg.arg
        return Not(arg, span=f.span)
    if isinstance(f, And):
        parts = _flatten(And, [simplify(a) for a in f.args])
        if any(p == FALSE for p in parts):
            return FALSE
        kept = list(dict.fromkeys(p for p in parts if p != TRUE))
        return conjoin(kept)
    if isinstance(f, Or):
        parts = _flatten(Or, [simplify(a) for a in f.args])
        if any(p == TRUE for p in parts):
            return TRUE
        kept = list(dict.fromkeys(p for p in parts if p != FALSE))
        return disjoin(kept)
    if isinstance(f, Eventually | Globally):
        arg = simplify(f.arg)
        if isinstance(arg, Const):
            return arg
        if isinstance(arg, type(f)):  # F F a = F a, G G a = G a
            return arg
        return type(f)(arg, span=f.span)
    if isinstance(f, Implies | Equiv | Until | Release | WeakUntil | StrongRelease):
        return type(f)(simplify(f.left), simplify(f.right), span=f.span)
    raise TypeError(f"not an LTL node: {f!r}")
