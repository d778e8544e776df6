"""The GR(1) specification IR shared by every reader and by the solver.

A :class:`GameSpec` is a two-player game: the environment owns the input variables and moves
first in every step, the system owns the outputs and answers (Mealy).  Variables are Boolean or
range-bounded integers.  The specification is a list of :class:`Part` objects, each one
conjunct of an initial condition, a safety (transition) constraint or a liveness goal of one
player, carrying the place in the source it came from so that unrealizability cores can point
at it.  Readers of the community formats (gr1c, slugs, TLSF) produce this IR; a game built
over the motion-planning abstraction can produce it as well.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

Owner = Literal["env", "sys"]
PartKind = Literal["init", "safety", "liveness"]
#: How initial states are quantified (each format's tool decides; see docs/synthesis.md).
#: ``forall_env_exists_sys``: for every environment start satisfying the environment's initial
#: condition some system start satisfying the system's must be winning (gr1c's default, slugs,
#: TLSF's Mealy reading); ``all_init``: every state satisfying both is winning (gr1c
#: ``-n ALL_INIT``, slugs ``--sysInitRoboticsSemantics``); ``one_side``: gr1c ``ONE_SIDE_INIT``.
InitMode = Literal["forall_env_exists_sys", "all_init", "one_side"]
INIT_MODES: tuple[InitMode, ...] = ("forall_env_exists_sys", "all_init", "one_side")


@dataclass(frozen=True, slots=True)
class Location:
    """A 1-based place in a source file."""

    file: str
    line: int
    col: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"


@dataclass(frozen=True, slots=True)
class Variable:
    """A game variable: Boolean when ``low``/``high`` are None, else an integer in
    ``[low, high]``."""

    name: str
    owner: Owner
    low: int | None = None
    high: int | None = None

    @property
    def is_bool(self) -> bool:
        """Whether the variable is Boolean."""
        return self.low is None


# --- expressions ---------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Const:
    """``True`` or ``False``."""

    value: bool


@dataclass(frozen=True, slots=True)
class Atom:
    """A Boolean variable, in the current step or (``primed``) the next one."""

    name: str
    primed: bool = False


@dataclass(frozen=True, slots=True)
class Compare:
    """An integer variable compared with a constant: ``name op value``."""

    name: str
    op: Literal["=", "!=", "<", "<=", ">", ">="]
    value: int
    primed: bool = False


@dataclass(frozen=True, slots=True)
class Linear:
    """A comparison of integer arithmetic over variables: ``sum(coef * var) op value``, with
    each term ``(coef, name, primed)``; exact integers, no overflow (slugs' structured
    format writes ``level' = level + 1``)."""

    terms: tuple[tuple[int, str, bool], ...]
    op: Literal["=", "!=", "<", "<=", ">", ">="]
    value: int


@dataclass(frozen=True, slots=True, eq=False)
class Not:
    """Negation."""

    arg: Expr


@dataclass(frozen=True, slots=True, eq=False)
class Nary:
    """Conjunction, disjunction or exclusive or of any number of operands."""

    op: Literal["and", "or", "xor"]
    args: tuple[Expr, ...]


@dataclass(frozen=True, slots=True, eq=False)
class Binary:
    """Implication or equivalence."""

    op: Literal["->", "<->"]
    left: Expr
    right: Expr


Expr = Const | Atom | Compare | Linear | Not | Nary | Binary


def walk(expr: Expr) -> list[Expr]:
    """Every node of ``expr`` once (expressions may share subtrees: slugs' memory buffers)."""
    seen: set[int] = set()
    order: list[Expr] = []
    stack: list[Expr] = [expr]
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        order.append(node)
        if isinstance(node, Not):
            stack.append(node.arg)
        elif isinstance(node, Nary):
            stack.extend(node.args)
        elif isinstance(node, Binary):
            stack.extend((node.left, node.right))
    return order


def support(expr: Expr) -> set[tuple[str, bool]]:
    """The ``(variable, primed)`` pairs that ``expr`` mentions."""
    found = {(n.name, n.primed) for n in walk(expr) if isinstance(n, Atom | Compare)}
    for node in walk(expr):
        if isinstance(node, Linear):
            found |= {(name, primed) for _, name, primed in node.terms}
    return found


# --- parts and the specification --------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Part:
    """One conjunct of the specification.

    ``kind`` ``init`` constrains the first state; ``safety`` constrains every step (a formula
    over the current and, primed, the next state); ``liveness`` must hold infinitely often (a
    state or, for slugs, a transition formula).  ``text`` is the source text, for reports.
    """

    owner: Owner
    kind: PartKind
    formula: Expr
    location: Location
    text: str

    @property
    def label(self) -> str:
        """``env init``, ``sys safety``, ... ."""
        return f"{self.owner} {self.kind}"


@dataclass(frozen=True, slots=True)
class GameSpec:
    """A GR(1) game: variables, parts, and the initial-state quantification of its source."""

    variables: tuple[Variable, ...]
    parts: tuple[Part, ...]
    init_mode: InitMode
    source_format: str
    file: str

    def variable(self, name: str) -> Variable:
        """The variable called ``name``."""
        for variable in self.variables:
            if variable.name == name:
                return variable
        raise KeyError(name)

    def owned(self, owner: Owner) -> tuple[Variable, ...]:
        """The variables of one player, in declaration order."""
        return tuple(v for v in self.variables if v.owner == owner)

    def select(self, owner: Owner, kind: PartKind) -> tuple[Part, ...]:
        """The parts of one player of one kind, in source order."""
        return tuple(p for p in self.parts if p.owner == owner and p.kind == kind)

    def with_parts(self, parts: tuple[Part, ...]) -> GameSpec:
        """The same game with another list of parts (used for cores)."""
        return GameSpec(self.variables, parts, self.init_mode, self.source_format, self.file)

    def with_init_mode(self, mode: InitMode) -> GameSpec:
        """The same game read with another initial-state quantification."""
        return GameSpec(self.variables, self.parts, mode, self.source_format, self.file)
