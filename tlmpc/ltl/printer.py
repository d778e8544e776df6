"""Print formulas: canonical tlmpc syntax (parseable, minimal parentheses) and SPIN syntax.

The canonical printer lives beside the formula classes (:func:`tlmpc.ltl.ast.to_text`, the
``str`` of a formula) and is re-exported here; this module adds SPIN's syntax.
"""

from __future__ import annotations

from typing import assert_never

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
    interval_text,
    proposition_text,
    seconds_text,
    to_text,
)

__all__ = ["interval_text", "proposition_text", "seconds_text", "to_spin", "to_text"]


def to_spin(formula: Formula) -> str:
    """The formula in SPIN's syntax (``[] <> ! && || -> <-> U V``), fully parenthesised.

    SPIN has no weak until or strong release: ``a W b`` is sent as ``b V (a || b)`` and
    ``a M b`` as ``b U (a && b)``.
    """
    match formula:
        case Const(value):
            return "true" if value else "false"
        case Prop(name):
            return name
        case Not(arg):
            return f"!({to_spin(arg)})"
        case Eventually(arg):
            return f"<>({to_spin(arg)})"
        case Globally(arg):
            return f"[]({to_spin(arg)})"
        case And(args):
            return "(" + " && ".join(to_spin(a) for a in args) + ")"
        case Or(args):
            return "(" + " || ".join(to_spin(a) for a in args) + ")"
        case Implies(left, right):
            return f"(({to_spin(left)}) -> ({to_spin(right)}))"
        case Equiv(left, right):
            return f"(({to_spin(left)}) <-> ({to_spin(right)}))"
        case Until(left, right):
            return f"(({to_spin(left)}) U ({to_spin(right)}))"
        case Release(left, right):
            return f"(({to_spin(left)}) V ({to_spin(right)}))"
        case WeakUntil(left, right):
            a, b = to_spin(left), to_spin(right)
            return f"(({b}) V (({a}) || ({b})))"
        case StrongRelease(left, right):
            a, b = to_spin(left), to_spin(right)
            return f"(({b}) U (({a}) && ({b})))"
        case BoundedEventually() | BoundedGlobally() | BoundedUntil():
            raise ValueError(
                f"SPIN has no time bounds: {to_text(formula)} cannot be written for it"
            )
        case _:
            assert_never(formula)
