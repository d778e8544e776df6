"""Print formulas: canonical tlmpc syntax (parseable, minimal parentheses) and SPIN syntax.

``parse_ltl(to_text(f)) == f`` for every formula (a property test checks it): nested n-ary
``&``/``|`` and left-nested ``U`` keep their parentheses, so the tree survives the trip.
Binary temporal operators inside Boolean ones are parenthesised for readability although
the precedence would not need it: ``p4 & ((!p2 & !p3) U p1)``.
"""

from __future__ import annotations

import re
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
    Interval,
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
)

# Binding strength, loosest first (Spot's order; `->` and `<->` share a level, right-assoc).
_IMPLIES, _OR, _AND, _BINTEMP, _UNARY, _ATOM = range(1, 7)

_TEMPORAL_SYMBOL = {Until: "U", Release: "R", WeakUntil: "W", StrongRelease: "M"}


_BARE_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_OPERATOR_CHAIN = re.compile(r"[FGXN]+")
#: Words the lexer reads as operators or constants wherever they may stand.
_RESERVED = frozenset({"U", "R", "W", "M", "V", "true", "false"})


def proposition_text(name: str) -> str:
    """``name`` as the parser reads it back: bare when it is an ASCII identifier that is no
    operator or constant (``U``, ``true``, ``FG``), else in double quotes with ``\\``,
    ``"`` and newlines escaped."""
    if _BARE_NAME.fullmatch(name) and name not in _RESERVED and not _OPERATOR_CHAIN.fullmatch(name):
        return name
    escaped = name.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return f'"{escaped}"'


def seconds_text(value: float) -> str:
    """A bound in seconds as the parser reads it back exactly: ``5``, ``0.25``, ``inf``."""
    if value == float("inf"):
        return "inf"
    if value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value)


def interval_text(interval: Interval) -> str:
    """``[a,b]``."""
    return f"[{seconds_text(interval.low)},{seconds_text(interval.high)}]"


def _level(formula: Formula) -> int:
    match formula:
        case Implies() | Equiv():
            return _IMPLIES
        case Or():
            return _OR
        case And():
            return _AND
        case Until() | Release() | WeakUntil() | StrongRelease() | BoundedUntil():
            return _BINTEMP
        case Not() | Eventually() | Globally() | BoundedEventually() | BoundedGlobally():
            return _UNARY
        case Const() | Prop():
            return _ATOM
        case _:
            assert_never(formula)


def _wrap(text: str, needed: bool) -> str:
    return f"({text})" if needed else text


def to_text(formula: Formula) -> str:
    """The formula in tlmpc's canonical syntax."""
    return _print(formula)


def _operand(child: Formula, minimum: int, *, boolean_parent: bool = False) -> str:
    level = _level(child)
    needed = level < minimum or (boolean_parent and level == _BINTEMP)
    return _wrap(_print(child), needed)


def _print(formula: Formula) -> str:
    match formula:
        case Const(value):
            return "true" if value else "false"
        case Prop(name):
            return proposition_text(name)
        case Not(arg):
            return "!" + _operand(arg, _UNARY)
        case Eventually(arg) | Globally(arg):
            symbol = "F" if isinstance(formula, Eventually) else "G"
            inner = _operand(arg, _UNARY)
            return f"{symbol}{inner}" if inner.startswith("(") else f"{symbol} {inner}"
        case And(args):
            return " & ".join(_operand(a, _AND + 1, boolean_parent=True) for a in args)
        case Or(args):
            return " | ".join(_operand(a, _OR + 1, boolean_parent=True) for a in args)
        case Implies(left, right) | Equiv(left, right):
            symbol = "->" if isinstance(formula, Implies) else "<->"
            left_text = _operand(left, _IMPLIES + 1, boolean_parent=True)
            right_text = _operand(right, _IMPLIES, boolean_parent=True)
            return f"{left_text} {symbol} {right_text}"
        case (
            Until(left, right)
            | Release(left, right)
            | WeakUntil(left, right)
            | StrongRelease(left, right)
        ):
            symbol = _TEMPORAL_SYMBOL[type(formula)]
            return f"{_operand(left, _BINTEMP + 1)} {symbol} {_operand(right, _BINTEMP)}"
        case BoundedEventually(arg, interval) | BoundedGlobally(arg, interval):
            symbol = "F" if isinstance(formula, BoundedEventually) else "G"
            return f"{symbol}{interval_text(interval)} {_operand(arg, _UNARY)}"
        case BoundedUntil(left, right, interval):
            left_text = _operand(left, _BINTEMP + 1)
            return f"{left_text} U{interval_text(interval)} {_operand(right, _BINTEMP)}"
        case _:
            assert_never(formula)


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
            raise ValueError(f"SPIN has no time bounds: {_print(formula)} cannot be written for it")
        case _:
            assert_never(formula)
