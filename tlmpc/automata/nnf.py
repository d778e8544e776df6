"""The translator's formulas: negation normal form as a closed union of small immutable nodes.

``Node = Top | Bottom | Pos | Neg | Conj | Disj | Finally | Always | Binary``.  Every node is a
named tuple whose first field is a one-character ``kind`` tag; conjunctions and disjunctions hold
a sorted tuple of distinct operands (see :mod:`tlmpc.automata.terms`), so equal formulas are
equal nodes and automaton states (sets of nodes) deduplicate for free.  Tuples keep hashing and
comparison in C, which the expansion relies on (it hashes and compares nodes millions of times);
``repr`` is the plain tuple's, a cheap canonical sort key.

Code that takes a node apart matches on the classes and ends with ``assert_never``, so adding a
kind without handling it everywhere fails the type check.
"""

from __future__ import annotations

from typing import Literal, NamedTuple


class Top(NamedTuple):
    """``true``."""

    kind: Literal["t"] = "t"


class Bottom(NamedTuple):
    """``false``."""

    kind: Literal["f"] = "f"


class Pos(NamedTuple):
    """A proposition."""

    kind: Literal["p"]
    name: str


class Neg(NamedTuple):
    """A negated proposition."""

    kind: Literal["n"]
    name: str


class Conj(NamedTuple):
    """A conjunction of at least two distinct operands, sorted."""

    kind: Literal["&"]
    args: tuple[Node, ...]


class Disj(NamedTuple):
    """A disjunction of at least two distinct operands, sorted."""

    kind: Literal["|"]
    args: tuple[Node, ...]


class Finally(NamedTuple):
    """``F arg``."""

    kind: Literal["F"]
    arg: Node


class Always(NamedTuple):
    """``G arg``."""

    kind: Literal["G"]
    arg: Node


BinaryKind = Literal["U", "R", "W", "M"]


class Binary(NamedTuple):
    """``left U right``, ``left R right``, ``left W right`` or ``left M right``."""

    kind: BinaryKind
    left: Node
    right: Node


Node = Top | Bottom | Pos | Neg | Conj | Disj | Finally | Always | Binary

for _node in (Top, Bottom, Pos, Neg, Conj, Disj, Finally, Always, Binary):
    # The plain tuple's repr, in C: the canonical sort key of operands and state conjuncts.
    setattr(_node, "__repr__", tuple.__repr__)  # noqa: B010 (a method of another class)

TRUE = Top()
FALSE = Bottom()


def pos(name: str) -> Pos:
    """The proposition ``name``."""
    return Pos("p", name)


def neg(name: str) -> Neg:
    """The negated proposition ``!name``."""
    return Neg("n", name)
