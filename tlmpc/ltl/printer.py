"""Print formulas: canonical tlmpc syntax (parseable, minimal parentheses), and SPIN's and
NuSMV's syntax.

The canonical printer lives beside the formula classes (:func:`tlmpc.ltl.ast.to_text`, the
``str`` of a formula) and is re-exported here; this module adds the model checkers' syntax.
"""

from __future__ import annotations

from dataclasses import dataclass
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

__all__ = [
    "interval_text",
    "proposition_text",
    "seconds_text",
    "to_nusmv",
    "to_spin",
    "to_text",
]


@dataclass(frozen=True, slots=True)
class _Checker:
    """How a model checker writes the operators that differ between SPIN and NuSMV."""

    tool: str
    true: str
    false: str
    eventually: str
    globally: str
    conjunction: str
    disjunction: str


_SPIN = _Checker("SPIN", "true", "false", "<>", "[]", " && ", " || ")
_NUSMV = _Checker("NuSMV", "TRUE", "FALSE", "F ", "G ", " & ", " | ")


def to_spin(formula: Formula) -> str:
    """The formula in SPIN's syntax (``[] <> ! && || -> <-> U V``), fully parenthesised.

    SPIN has no weak until or strong release: ``a W b`` is sent as ``b V (a || b)`` and
    ``a M b`` as ``b U (a && b)``.
    """
    return _checker_text(formula, _SPIN)


def to_nusmv(formula: Formula) -> str:
    """The formula in NuSMV's LTL syntax (``G F U V ! & | -> <-> TRUE FALSE``), fully
    parenthesised.

    NuSMV's constants are upper case (``true`` is an identifier there, unlike in SPIN), and
    it has no weak until or strong release either: ``a W b`` is written ``b V (a | b)`` and
    ``a M b`` ``b U (a & b)``.
    """
    return _checker_text(formula, _NUSMV)


def _checker_text(formula: Formula, checker: _Checker) -> str:
    def text(f: Formula) -> str:
        return _checker_text(f, checker)

    match formula:
        case Const(value):
            return checker.true if value else checker.false
        case Prop(name):
            return name
        case Not(arg):
            return f"!({text(arg)})"
        case Eventually(arg):
            return f"{checker.eventually}({text(arg)})"
        case Globally(arg):
            return f"{checker.globally}({text(arg)})"
        case And(args):
            return "(" + checker.conjunction.join(text(a) for a in args) + ")"
        case Or(args):
            return "(" + checker.disjunction.join(text(a) for a in args) + ")"
        case Implies(left, right):
            return f"(({text(left)}) -> ({text(right)}))"
        case Equiv(left, right):
            return f"(({text(left)}) <-> ({text(right)}))"
        case Until(left, right):
            return f"(({text(left)}) U ({text(right)}))"
        case Release(left, right):
            return f"(({text(left)}) V ({text(right)}))"
        case WeakUntil(left, right):
            a, b = text(left), text(right)
            return f"(({b}) V (({a}){checker.disjunction}({b})))"
        case StrongRelease(left, right):
            a, b = text(left), text(right)
            return f"(({b}) U (({a}){checker.conjunction}({b})))"
        case BoundedEventually() | BoundedGlobally() | BoundedUntil():
            raise ValueError(
                f"{checker.tool} has no time bounds: {to_text(formula)} cannot be written for it"
            )
        case _:
            assert_never(formula)
