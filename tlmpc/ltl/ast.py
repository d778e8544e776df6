"""The LTL abstract syntax tree: frozen, hashable nodes with optional source spans.

Every stage that reads formulas (task phrases, the automaton translator, the verifier) shares
these nodes.  ``And``/``Or`` are n-ary (at least two operands); the parser flattens chains
``a & b & c`` into one node.  Spans never take part in equality or hashing, so two formulas
parsed from different places compare equal when they mean the same tree.

There is deliberately no ``Next`` node: Next has no meaning in continuous time.

The time-bounded operators ``F[a,b]``, ``G[a,b]`` and ``U[a,b]`` (metric temporal logic over
continuous time, bounds in seconds) are nodes of their own, so that code written for the
untimed operators cannot mistake one for its unbounded namesake and drop the bound.

``Formula`` is a closed union of the node classes, not a base class: code that takes a formula
apart does it with ``match`` and ends in ``case _: assert_never(formula)``, so mypy rejects a
``match`` that forgets a node kind (a test checks that it does).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import TypeAlias, assert_never, cast


@dataclass(frozen=True, slots=True)
class Span:
    """Where a node came from: 1-based line/column of its first and last character."""

    line: int
    col: int
    end_line: int
    end_col: int


@dataclass(frozen=True, slots=True)
class Node:
    """Shared behaviour of the LTL node classes (annotate with ``Formula``, the closed union)."""

    def children(self) -> tuple[Formula, ...]:
        """Direct sub-formulas, left to right."""
        return ()

    def walk(self) -> Iterator[Formula]:
        """This node and every sub-formula, pre-order."""
        # Every Node subclass is a member of the Formula union (a test checks it).
        stack: list[Formula] = [cast("Formula", self)]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(node.children()))

    def props(self) -> frozenset[str]:
        """Names of the atomic propositions that occur in the formula."""
        return frozenset(n.name for n in self.walk() if isinstance(n, Prop))

    def __str__(self) -> str:
        return to_text(cast("Formula", self))


@dataclass(frozen=True, slots=True)
class Const(Node):
    """``true`` or ``false``."""

    value: bool
    span: Span | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True, slots=True)
class Prop(Node):
    """An atomic proposition: the robot is in the region (or group) of this name."""

    name: str
    span: Span | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True, slots=True)
class Not(Node):
    """``!arg``."""

    arg: Formula
    span: Span | None = field(default=None, compare=False, repr=False)

    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)


@dataclass(frozen=True, slots=True)
class And(Node):
    """``a & b & ...`` (two or more operands)."""

    args: tuple[Formula, ...]
    span: Span | None = field(default=None, compare=False, repr=False)

    def children(self) -> tuple[Formula, ...]:
        return self.args


@dataclass(frozen=True, slots=True)
class Or(Node):
    """``a | b | ...`` (two or more operands)."""

    args: tuple[Formula, ...]
    span: Span | None = field(default=None, compare=False, repr=False)

    def children(self) -> tuple[Formula, ...]:
        return self.args


@dataclass(frozen=True, slots=True)
class _Binary(Node):
    left: Formula
    right: Formula
    span: Span | None = field(default=None, compare=False, repr=False)

    def children(self) -> tuple[Formula, ...]:
        return (self.left, self.right)


@dataclass(frozen=True, slots=True)
class Implies(_Binary):
    """``left -> right``."""


@dataclass(frozen=True, slots=True)
class Equiv(_Binary):
    """``left <-> right``."""


@dataclass(frozen=True, slots=True)
class Until(_Binary):
    """``left U right`` (strong, non-strict until)."""


@dataclass(frozen=True, slots=True)
class Release(_Binary):
    """``left R right``: right holds until and including when left holds (or forever)."""


@dataclass(frozen=True, slots=True)
class WeakUntil(_Binary):
    """``left W right`` = ``(left U right) | G left``."""


@dataclass(frozen=True, slots=True)
class StrongRelease(_Binary):
    """``left M right`` = ``(left R right) & F left``."""


@dataclass(frozen=True, slots=True)
class Eventually(Node):
    """``F arg`` (also written ``<>``)."""

    arg: Formula
    span: Span | None = field(default=None, compare=False, repr=False)

    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)


@dataclass(frozen=True, slots=True)
class Globally(Node):
    """``G arg`` (also written ``[]``)."""

    arg: Formula
    span: Span | None = field(default=None, compare=False, repr=False)

    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)


@dataclass(frozen=True, slots=True)
class Interval:
    """A closed interval of seconds ``[low, high]``: ``0 <= low <= high``, ``high`` may be
    ``inf`` (the parser refuses anything else)."""

    low: float
    high: float

    def __post_init__(self) -> None:
        # seconds are floats, however given (Interval(0, 5) equals Interval(0.0, 5.0) anyway)
        object.__setattr__(self, "low", float(self.low))
        object.__setattr__(self, "high", float(self.high))
        if not (0.0 <= self.low <= self.high) or self.low == float("inf"):
            raise ValueError(f"not an interval of seconds: [{self.low}, {self.high}]")


@dataclass(frozen=True, slots=True)
class BoundedEventually(Node):
    """``F[a,b] arg``: ``arg`` holds at some instant of ``[t + a, t + b]``."""

    arg: Formula
    interval: Interval
    span: Span | None = field(default=None, compare=False, repr=False)

    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)


@dataclass(frozen=True, slots=True)
class BoundedGlobally(Node):
    """``G[a,b] arg``: ``arg`` holds at every instant of ``[t + a, t + b]``."""

    arg: Formula
    interval: Interval
    span: Span | None = field(default=None, compare=False, repr=False)

    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)


@dataclass(frozen=True, slots=True)
class BoundedUntil(Node):
    """``left U[a,b] right``: ``right`` at some ``s`` in ``[t + a, t + b]``, ``left`` on
    ``[t, s)``."""

    left: Formula
    right: Formula
    interval: Interval
    span: Span | None = field(default=None, compare=False, repr=False)

    def children(self) -> tuple[Formula, ...]:
        return (self.left, self.right)


Formula: TypeAlias = (
    Const
    | Prop
    | Not
    | And
    | Or
    | Implies
    | Equiv
    | Until
    | Release
    | WeakUntil
    | StrongRelease
    | Eventually
    | Globally
    | BoundedEventually
    | BoundedGlobally
    | BoundedUntil
)
"""An LTL formula: one of the node classes above (a closed union)."""

TRUE = Const(True)
FALSE = Const(False)

BINARY_TEMPORAL = (Until, Release, WeakUntil, StrongRelease)
UNARY_TEMPORAL = (Eventually, Globally)
BOUNDED = (BoundedEventually, BoundedGlobally, BoundedUntil)


def is_temporal(node: Formula) -> bool:
    """True for a temporal operator node (``U R W M F G``), False for the others."""
    match node:
        case Until() | Release() | WeakUntil() | StrongRelease() | Eventually() | Globally():
            return True
        case BoundedEventually() | BoundedGlobally() | BoundedUntil():
            return True
        case Const() | Prop() | Not() | And() | Or() | Implies() | Equiv():
            return False
        case _:
            assert_never(node)


def is_propositional(formula: Formula) -> bool:
    """True when the formula has no temporal operator."""
    return not any(is_temporal(n) for n in formula.walk())


def bounded_operators(formula: Formula) -> list[Formula]:
    """The time-bounded operators of ``formula`` (``F[a,b]``, ``G[a,b]``, ``U[a,b]``), pre-order."""
    return [n for n in formula.walk() if isinstance(n, BOUNDED)]


def conjoin(parts: list[Formula] | tuple[Formula, ...]) -> Formula:
    """The conjunction of ``parts`` (``true`` when empty, the part itself when one)."""
    flat: list[Formula] = []
    for part in parts:
        flat.extend(part.args if isinstance(part, And) else (part,))
    if not flat:
        return TRUE
    if len(flat) == 1:
        return flat[0]
    return And(tuple(flat))


def disjoin(parts: list[Formula] | tuple[Formula, ...]) -> Formula:
    """The disjunction of ``parts`` (``false`` when empty, the part itself when one)."""
    flat: list[Formula] = []
    for part in parts:
        flat.extend(part.args if isinstance(part, Or) else (part,))
    if not flat:
        return FALSE
    if len(flat) == 1:
        return flat[0]
    return Or(tuple(flat))


# --- the canonical text of a formula -------------------------------------------------------

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
