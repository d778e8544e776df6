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
        from tlmpc.ltl.printer import to_text

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
