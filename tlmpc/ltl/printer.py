"""Print formulas: canonical tlmpc syntax (parseable, minimal parentheses) and SPIN syntax.

``parse_ltl(to_text(f)) == f`` for every formula (a property test checks it): nested n-ary
``&``/``|`` and left-nested ``U`` keep their parentheses, so the tree survives the trip.
Binary temporal operators inside Boolean ones are parenthesised for readability although
the precedence would not need it: ``p4 & ((!p2 & !p3) U p1)``.
"""

from __future__ import annotations

import re

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


def _level(formula: Formula) -> int:
    if isinstance(formula, Implies | Equiv):
        return _IMPLIES
    if isinstance(formula, Or):
        return _OR
    if isinstance(formula, And):
        return _AND
    if isinstance(formula, Until | Release | WeakUntil | StrongRelease):
        return _BINTEMP
    if isinstance(formula, Not | Eventually | Globally):
        return _UNARY
    return _ATOM


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
    if isinstance(formula, Const):
        return "true" if formula.value else "false"
    if isinstance(formula, Prop):
        return proposition_text(formula.name)
    if isinstance(formula, Not):
        return "!" + _operand(formula.arg, _UNARY)
    if isinstance(formula, Eventually | Globally):
        symbol = "F" if isinstance(formula, Eventually) else "G"
        inner = _operand(formula.arg, _UNARY)
        return f"{symbol}{inner}" if inner.startswith("(") else f"{symbol} {inner}"
    if isinstance(formula, And):
        return " & ".join(_operand(a, _AND + 1, boolean_parent=True) for a in formula.args)
    if isinstance(formula, Or):
        return " | ".join(_operand(a, _OR + 1, boolean_parent=True) for a in formula.args)
    if isinstance(formula, Implies | Equiv):
        symbol = "->" if isinstance(formula, Implies) else "<->"
        left = _operand(formula.left, _IMPLIES + 1, boolean_parent=True)
        right = _operand(formula.right, _IMPLIES, boolean_parent=True)
        return f"{left} {symbol} {right}"
    if isinstance(formula, Until | Release | WeakUntil | StrongRelease):
        symbol = _TEMPORAL_SYMBOL[type(formula)]
        left = _operand(formula.left, _BINTEMP + 1)
        right = _operand(formula.right, _BINTEMP)
        return f"{left} {symbol} {right}"
    raise TypeError(f"not an LTL node: {formula!r}")


def to_spin(formula: Formula) -> str:
    """The formula in SPIN's syntax (``[] <> ! && || -> <-> U V``), fully parenthesised.

    SPIN has no weak until or strong release: ``a W b`` is sent as ``b V (a || b)`` and
    ``a M b`` as ``b U (a && b)``.
    """
    if isinstance(formula, Const):
        return "true" if formula.value else "false"
    if isinstance(formula, Prop):
        return formula.name
    if isinstance(formula, Not):
        return f"!({to_spin(formula.arg)})"
    if isinstance(formula, Eventually):
        return f"<>({to_spin(formula.arg)})"
    if isinstance(formula, Globally):
        return f"[]({to_spin(formula.arg)})"
    if isinstance(formula, And):
        return "(" + " && ".join(to_spin(a) for a in formula.args) + ")"
    if isinstance(formula, Or):
        return "(" + " || ".join(to_spin(a) for a in formula.args) + ")"
    if isinstance(formula, Implies):
        return f"(({to_spin(formula.left)}) -> ({to_spin(formula.right)}))"
    if isinstance(formula, Equiv):
        return f"(({to_spin(formula.left)}) <-> ({to_spin(formula.right)}))"
    if isinstance(formula, Until):
        return f"(({to_spin(formula.left)}) U ({to_spin(formula.right)}))"
    if isinstance(formula, Release):
        return f"(({to_spin(formula.left)}) V ({to_spin(formula.right)}))"
    if isinstance(formula, WeakUntil):
        a, b = to_spin(formula.left), to_spin(formula.right)
        return f"(({b}) V (({a}) || ({b})))"
    if isinstance(formula, StrongRelease):
        a, b = to_spin(formula.left), to_spin(formula.right)
        return f"(({b}) U (({a}) && ({b})))"
    raise TypeError(f"not an LTL node: {formula!r}")
