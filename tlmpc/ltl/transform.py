"""Rewrites of LTL formulas: negation normal form, substitution, syntactic classes.

NNF keeps ``W``/``M``/``R`` as native operators (expanding ``W`` duplicates a subformula)
and uses the dualities ``!(a U b) = !a R !b``, ``!(a R b) = !a U !b``,
``!(a W b) = !a M !b``, ``!(a M b) = !a W !b``, ``!F a = G !a``, ``!G a = F !a``.
The bounded operators dualise as ``!F[a,b] x = G[a,b] !x`` and ``!G[a,b] x = F[a,b] !x``; a
negated bounded until has no dual in the language (there is no bounded release), so NNF keeps
``!(x U[a,b] y)`` with its operands in NNF: the only negation above a non-proposition.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import assert_never

from tlmpc.base.errors import Diagnostic, UsageError, error
from tlmpc.ltl.ast import (
    FALSE,
    TRUE,
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


#: The most operators and names a negation normal form may have.  ``a <-> b`` is written
#: ``(a & b) | (!a & !b)``, both sides twice, so a chain of n equivalences has about 2^n of
#: them: past this size building (and then translating) it would take minutes and gigabytes.
MAX_NORMAL_FORM_SIZE = 200_000


def normal_form_size(formula: Formula, negate: bool = False) -> int:
    """An upper bound of the number of operators and names :func:`nnf` writes for ``formula``
    (its negation when ``negate``; exact but for the ``&``/``|`` it flattens), counted in time
    linear in the formula's own size."""
    # iterative, so that it takes formulas as deep as the parser does (L005) from any stack;
    # keyed by id: a node's operands are alive as long as the formula is
    sizes: dict[tuple[int, bool], int] = {}
    stack: list[tuple[Formula, bool, bool]] = [(formula, negate, False)]
    while stack:
        node, negated, operands_done = stack.pop()
        operands = _nnf_children(node, negated)
        if operands_done:
            own = _own_size(node, negated)
            sizes[(id(node), negated)] = own + sum(sizes[(id(a), f)] for a, f in operands)
        elif (id(node), negated) not in sizes:
            stack.append((node, negated, True))
            stack.extend((a, f, False) for a, f in operands if (id(a), f) not in sizes)
    return sizes[(id(formula), negate)]


def _own_size(node: Formula, negated: bool) -> int:
    match node:
        case Prop():
            return 2 if negated else 1
        case Not():
            return 0
        case Equiv():
            return 3  # the disjunction of two conjunctions
        case BoundedUntil():
            return 2 if negated else 1
        case _:
            return 1


def _nnf_children(node: Formula, negated: bool) -> list[tuple[Formula, bool]]:
    """The operands :func:`nnf` puts into the normal form of ``node``, with their polarity."""
    match node:
        case Not(arg):
            return [(arg, not negated)]
        case Implies(left, right):
            return [(left, not negated), (right, negated)]
        case Equiv(left, right):
            return [(left, False), (left, True), (right, False), (right, True)]
        case BoundedUntil(left, right, _):
            return [(left, False), (right, False)]
        case _:
            return [(child, negated) for child in node.children()]


def normal_form_refusal(formula: Formula, negate: bool = False) -> Diagnostic | None:
    """P041 when the negation normal form of ``formula`` (of its negation when ``negate``)
    would have more than :data:`MAX_NORMAL_FORM_SIZE` operators and names; None otherwise."""
    if normal_form_size(formula, negate) <= MAX_NORMAL_FORM_SIZE:
        return None
    return error(
        "P041",
        "the formula's negation normal form would have more than "
        f"{MAX_NORMAL_FORM_SIZE:,} operators and names, more than the translation's "
        "budget: each `<->` writes both of its sides twice",
        hint="write fewer nested `<->` (a chain of n equivalences doubles n times), "
        "or split the task into smaller missions",
    )


def nnf(formula: Formula, negate: bool = False) -> Formula:
    """Negation normal form of ``formula`` (of its negation when ``negate``).

    The result has no ``->``/``<->`` and negations only directly above propositions.

    Raises:
        UsageError: P041 (:func:`normal_form_refusal`), the normal form would have more than
            :data:`MAX_NORMAL_FORM_SIZE` operators and names (chains of ``<->``).
    """
    refusal = normal_form_refusal(formula, negate)
    if refusal is not None:
        raise UsageError(refusal)
    return _nnf(formula, negate)


def _nnf(formula: Formula, negate: bool) -> Formula:
    match formula:
        case Const(value):
            return Const(value != negate)
        case Prop(name):
            return Not(formula) if negate else Prop(name)
        case Not(arg):
            return _nnf(arg, not negate)
        case And(args) | Or(args):
            parts = [_nnf(a, negate) for a in args]
            use_and = isinstance(formula, And) != negate
            return conjoin(parts) if use_and else disjoin(parts)
        case Implies(left, right):
            # a -> b  ==  !a | b ;  !(a -> b)  ==  a & !b
            if negate:
                return conjoin([_nnf(left, False), _nnf(right, True)])
            return disjoin([_nnf(left, True), _nnf(right, False)])
        case Equiv(left, right):
            # a <-> b == (a & b) | (!a & !b);  !(a <-> b) == (a & !b) | (!a & b)
            a, na = _nnf(left, False), _nnf(left, True)
            b, nb = _nnf(right, False), _nnf(right, True)
            if negate:
                return disjoin([conjoin([a, nb]), conjoin([na, b])])
            return disjoin([conjoin([a, b]), conjoin([na, nb])])
        case Eventually(arg):
            return Globally(_nnf(arg, True)) if negate else Eventually(_nnf(arg, False))
        case Globally(arg):
            return Eventually(_nnf(arg, True)) if negate else Globally(_nnf(arg, False))
        case (
            Until(left, right)
            | Release(left, right)
            | WeakUntil(left, right)
            | StrongRelease(left, right)
        ):
            build = _DUAL[type(formula)] if negate else _SAME[type(formula)]
            return build(_nnf(left, negate), _nnf(right, negate))
        case BoundedEventually(arg, interval):
            if negate:
                return BoundedGlobally(_nnf(arg, True), interval)
            return BoundedEventually(_nnf(arg, False), interval)
        case BoundedGlobally(arg, interval):
            if negate:
                return BoundedEventually(_nnf(arg, True), interval)
            return BoundedGlobally(_nnf(arg, False), interval)
        case BoundedUntil(left, right, interval):
            until = BoundedUntil(_nnf(left, False), _nnf(right, False), interval)
            return Not(until) if negate else until
        case _:
            assert_never(formula)


def substitute(formula: Formula, replace: Mapping[str, Formula]) -> Formula:
    """``formula`` with every proposition named in ``replace`` replaced (spans kept)."""
    f = formula
    match f:
        case Prop(name):
            return replace.get(name, f)
        case Const():
            return f
        case Not(arg):
            return Not(substitute(arg, replace), span=f.span)
        case And(args):
            return And(tuple(substitute(a, replace) for a in args), span=f.span)
        case Or(args):
            return Or(tuple(substitute(a, replace) for a in args), span=f.span)
        case Eventually(arg):
            return Eventually(substitute(arg, replace), span=f.span)
        case Globally(arg):
            return Globally(substitute(arg, replace), span=f.span)
        case (
            Implies(left, right)
            | Equiv(left, right)
            | Until(left, right)
            | Release(left, right)
            | WeakUntil(left, right)
            | StrongRelease(left, right)
        ):
            return type(f)(substitute(left, replace), substitute(right, replace), span=f.span)
        case BoundedEventually(arg, interval) | BoundedGlobally(arg, interval):
            return type(f)(substitute(arg, replace), interval, span=f.span)
        case BoundedUntil(left, right, interval):
            return BoundedUntil(
                substitute(left, replace), substitute(right, replace), interval, span=f.span
            )
        case _:
            assert_never(f)


def _only(formula: Formula, allowed: tuple[type, ...]) -> bool:
    # A bounded operator is in neither class: the classes are the automaton planner's, which
    # does not take bounds.
    for node in nnf(formula).walk():
        if isinstance(node, BoundedEventually | BoundedGlobally | BoundedUntil):
            return False
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
    match f:
        case Const() | Prop():
            return f
        case Not(arg):
            arg = simplify(arg)
            if isinstance(arg, Const):
                return Const(not arg.value)
            if isinstance(arg, Not):
                return arg.arg
            return Not(arg, span=f.span)
        case And(args):
            parts = _flatten(And, [simplify(a) for a in args])
            if any(p == FALSE for p in parts):
                return FALSE
            return conjoin(list(dict.fromkeys(p for p in parts if p != TRUE)))
        case Or(args):
            parts = _flatten(Or, [simplify(a) for a in args])
            if any(p == TRUE for p in parts):
                return TRUE
            return disjoin(list(dict.fromkeys(p for p in parts if p != FALSE)))
        case Eventually(arg) | Globally(arg):
            arg = simplify(arg)
            if isinstance(arg, Const):
                return arg
            if isinstance(arg, type(f)):  # F F a = F a, G G a = G a
                return arg
            return type(f)(arg, span=f.span)
        case (
            Implies(left, right)
            | Equiv(left, right)
            | Until(left, right)
            | Release(left, right)
            | WeakUntil(left, right)
            | StrongRelease(left, right)
        ):
            return type(f)(simplify(left), simplify(right), span=f.span)
        case BoundedEventually(arg, interval) | BoundedGlobally(arg, interval):
            arg = simplify(arg)
            if isinstance(arg, Const):  # the window is never empty
                return arg
            return type(f)(arg, interval, span=f.span)
        case BoundedUntil(left, right, interval):
            return BoundedUntil(simplify(left), simplify(right), interval, span=f.span)
        case _:
            assert_never(f)
