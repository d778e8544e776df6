"""Implication-based rewriting of the translator's formulas (Somenzi–Bloem; the rules Spot's
``tl_simplifier`` applies with syntactic implication checks).

Bottom-up, every node is rebuilt from its rewritten operands, then the rules below apply, each
decided by the sound syntactic implication check :func:`tlmpc.automata.terms.implies` (never
by a translation, so the pass is cheap enough to run on every formula):

==================  ====================  ======================
node                becomes               when
==================  ====================  ======================
``a | b``           ``b``                 a ⇒ b
``a | b``           ``true``              ¬a ⇒ b
``a & b``           ``a``                 a ⇒ b
``a & b``           ``false``             a ⇒ ¬b
``a U b``           ``b``                 a ⇒ b
``a U b``           ``F b``               ¬a ⇒ b
``a W b``           ``b``                 a ⇒ b
``a W b``           ``true``              ¬a ⇒ b
``a R b``           ``b``                 b ⇒ a
``a R b``           ``G b``               b ⇒ ¬a
``a M b``           ``b``                 b ⇒ a
``a M b``           ``false``             b ⇒ ¬a
``a U (b U c)``     ``b U c``             a ⇒ b
``a W (b W c)``     ``b W c``             a ⇒ b
``a R (b R c)``     ``b R c``             b ⇒ a
``a M (b M c)``     ``b M c``             b ⇒ a
==================  ====================  ======================

Beside them: ``G F(a R b) = G F a`` (a ⇒ b, b ⇒ F a), ``F(a | b) = F b`` (F a ⇒ F b),
``G(a & b) = G b`` (G b ⇒ G a), ``G F(a | b) = G F b`` (G F a ⇒ G F b), ``a U G c = G c``
(a ⇒ c), ``G d U b = b`` (d ⇒ ¬b), ``a U b = F b`` (F b ⇒ a), ``a R F c = F c`` (c ⇒ a),
``F c R b = b`` (¬c ⇒ b), Spot's ``a U (a & b) = b M a`` (and duals), and the literal
assumptions ``x | F ℓ = x[ℓ := false] | F ℓ``, ``x & G ℓ = x[ℓ := true] & G ℓ``.

Why they hold: for ``a U b`` with a ⇒ b, wherever ``a`` holds so does ``b``, so the until is
fulfilled at once or never needed ``a``; with ¬a ⇒ b every position before the first ``b`` has
``a``.  The ``R``/``M`` rules are the duals (``¬(a U b) = ¬a R ¬b``, ``¬(a W b) = ¬a M ¬b``).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import assert_never

from tlmpc.automata import work
from tlmpc.automata.nnf import (
    FALSE,
    TRUE,
    Always,
    Binary,
    BinaryKind,
    Bottom,
    Conj,
    Disj,
    Finally,
    Neg,
    Node,
    Pos,
    Top,
    neg,
    pos,
)
from tlmpc.automata.terms import (
    implies,
    is_pure_eventuality,
    make_and,
    make_binary,
    make_f,
    make_g,
    make_or,
)

#: Nodes with more operands are rebuilt without the pairwise checks (they are quadratic).
MAX_OPERANDS = 12
#: Semantic implication checks only for nodes with at most this many operands.
MAX_SEMANTIC_OPERANDS = 4
#: ... and for formulas over at most this many propositions (the caller checks).
MAX_SEMANTIC_APS = 6

_DUAL: dict[BinaryKind, BinaryKind] = {"U": "R", "R": "U", "W": "M", "M": "W"}
_TEMPORAL = Finally | Always | Binary


@functools.lru_cache(maxsize=1 << 16)
def negate(f: Node) -> Node:
    """The negation normal form of ``!f`` (rebuilt through the simplifying constructors).

    Memoized: the pairwise checks of a junction negate the same operands again and again, and
    a nest of ``<->`` doubles its operands at each level."""
    match f:
        case Top():
            return FALSE
        case Bottom():
            return TRUE
        case Pos(name=name):
            return neg(name)
        case Neg(name=name):
            return pos(name)
        case Conj(args=args):
            return make_or([negate(a) for a in args])
        case Disj(args=args):
            return make_and([negate(a) for a in args])
        case Finally(arg=arg):
            return make_g(negate(arg))
        case Always(arg=arg):
            return make_f(negate(arg))
        case Binary(kind=kind, left=left, right=right):
            return make_binary(_DUAL[kind], negate(left), negate(right))
        case _:
            assert_never(f)


def rewrite(f: Node, empty: Callable[[Node], bool] | None = None, deadline: float = 0.0) -> Node:
    """``f`` with the implication rules of the module docstring applied at every node.

    With ``empty`` (a language-emptiness oracle), an implication the syntactic check misses is
    also decided semantically (``a ⇒ b`` iff ``a & !b`` is empty), and a temporal node whose
    language is empty (or universal) becomes ``false`` (``true``); only until the work
    count (:mod:`tlmpc.automata.work`) passes ``deadline``, on formulas over at most
    :data:`MAX_SEMANTIC_APS` propositions and nodes of at most :data:`MAX_SEMANTIC_OPERANDS`
    operands."""
    return _Rewriter(empty, deadline).run(f)


class _Rewriter:
    def __init__(self, empty: Callable[[Node], bool] | None, deadline: float) -> None:
        self.empty = empty
        self.deadline = deadline
        self.memo: dict[Node, Node] = {}
        self.semantic_memo: dict[tuple[Node, Node], bool] = {}

    def semantic(self) -> bool:
        return self.empty is not None and not work.over(self.deadline)

    def implies(self, f: Node, g: Node, *, small: bool = True) -> bool:
        if implies(f, g):
            return True
        if not small or not self.semantic():
            return False
        key = (f, g)
        known = self.semantic_memo.get(key)
        if known is None:
            assert self.empty is not None
            known = self.empty(make_and([f, negate(g)]))
            self.semantic_memo[key] = known
        return known

    def run(self, f: Node) -> Node:
        done = self.memo.get(f)
        if done is not None:
            return done
        result: Node
        match f:
            case Top() | Bottom() | Pos() | Neg():
                result = f
            case Conj(args=args):
                result = self.junction(True, [self.run(a) for a in args])
            case Disj(args=args):
                result = self.junction(False, [self.run(a) for a in args])
            case Finally(arg=arg):
                result = self.under_f(make_f(self.run(arg)))
            case Always(arg=arg):
                result = self.under_g(make_g(self.run(arg)))
            case Binary(kind=kind, left=left, right=right):
                result = self.binary(kind, self.run(left), self.run(right))
            case _:
                assert_never(f)
        if isinstance(result, _TEMPORAL) and self.semantic():
            assert self.empty is not None
            if self.empty(result):
                result = FALSE
            elif self.empty(negate(result)):
                result = TRUE
        self.memo[f] = result
        return result

    def under_f(self, f: Node) -> Node:
        # F(a | b) = F b when F a ⇒ F b (F(p | G F p) = F p).
        if isinstance(f, Finally) and isinstance(f.arg, Disj):
            kept = self.absorbed(list(f.arg.args), make_f, make_or)
            if kept is not None:
                return make_f(kept)
        return f

    def under_g(self, f: Node) -> Node:
        # G(a & b) = G b when G b ⇒ G a (the dual), and inside G F, G F(a | b) = G F b when
        # G F a ⇒ G F b (G F((p1 R p0) | G F p0) = G F p0).
        if isinstance(f, Always) and isinstance(f.arg, Conj):
            kept = self.absorbed(list(f.arg.args), make_g, make_and, weaker_drops=True)
            if kept is not None:
                return make_g(kept)
        if (
            isinstance(f, Always)
            and isinstance(f.arg, Finally)
            and isinstance(f.arg.arg, Binary)
            and f.arg.arg.kind == "R"
            and self.implies(f.arg.arg.left, f.arg.arg.right)
            and self.implies(f.arg.arg.right, make_f(f.arg.arg.left))
        ):
            # G F(a R b) = G F a when a ⇒ b and b ⇒ F a: a R b holds wherever a does, and
            # a R b implies b, hence F a.
            return make_g(make_f(f.arg.arg.left))
        if isinstance(f, Always) and isinstance(f.arg, Finally) and isinstance(f.arg.arg, Disj):
            kept = self.absorbed(list(f.arg.arg.args), lambda d: make_g(make_f(d)), make_or)
            if kept is not None:
                return make_g(make_f(kept))
        return f

    def absorbed(
        self,
        items: list[Node],
        wrap: Callable[[Node], Node],
        join: Callable[[list[Node]], Node],
        *,
        weaker_drops: bool = False,
    ) -> Node | None:
        """``join`` of ``items`` without those made redundant under ``wrap`` by another
        remaining one (a disjunct whose wrapped form implies another's; with
        ``weaker_drops``, a conjunct whose wrapped form another's implies), or None."""
        if len(items) > MAX_OPERANDS:
            return None
        small = len(items) <= MAX_SEMANTIC_OPERANDS
        wrapped = {item: wrap(item) for item in items}
        kept = list(items)
        for item in items:
            if any(
                other is not item
                and (
                    self.implies(wrapped[other], wrapped[item], small=small)
                    if weaker_drops
                    else self.implies(wrapped[item], wrapped[other], small=small)
                )
                for other in kept
            ):
                kept.remove(item)
        return None if len(kept) == len(items) else join(kept)

    def junction(self, conjunction: bool, args: list[Node]) -> Node:
        built = make_and(args) if conjunction else make_or(args)
        if not isinstance(built, Conj if conjunction else Disj):
            return built
        assert isinstance(built, Conj | Disj)
        if len(built.args) > MAX_OPERANDS:
            return built
        items = list(built.args)
        substituted = _assume_literals(items, conjunction)
        if substituted != items:
            return self.junction(conjunction, substituted)
        small = len(items) <= MAX_SEMANTIC_OPERANDS
        for index, item in enumerate(items):
            for other in items[index + 1 :]:
                if conjunction and (implies(item, negate(other)) or implies(other, negate(item))):
                    return FALSE
                if not conjunction and (
                    implies(negate(item), other) or implies(negate(other), item)
                ):
                    return TRUE
        # Drop, one at a time, an operand that another remaining one makes redundant (so of
        # two equivalent operands one stays).
        kept = list(items)
        for item in items:
            if any(
                other is not item
                and (
                    self.implies(other, item, small=small)
                    if conjunction
                    else self.implies(item, other, small=small)
                )
                for other in kept
            ):
                kept.remove(item)
        if len(kept) == len(items):
            return built
        return make_and(kept) if conjunction else make_or(kept)

    def binary(self, kind: BinaryKind, a: Node, b: Node) -> Node:
        if kind in ("U", "W"):
            if self.implies(a, b):
                return b
            if self.implies(negate(a), b):
                return make_f(b) if kind == "U" else TRUE
            if isinstance(b, Binary) and b.kind == kind and self.implies(a, b.left):
                return b
            if isinstance(b, Always) and self.implies(a, b.arg):
                # a U G c = a W G c = G c when a ⇒ c: the positions before G c have c too.
                return b
            if kind == "U" and isinstance(a, Always) and self.implies(a.arg, negate(b)):
                # G d U b = b when d ⇒ ¬b: b cannot come after a position of G d (G d W b
                # is G d | b already).
                return b
            if isinstance(b, Conj) and a in b.args:
                # a U (a & b) = b M a and a W (a & b) = b R a (Spot's rules).
                rest = make_and([x for x in b.args if x != a])
                return make_binary("M" if kind == "U" else "R", rest, a)
            if kind == "U" and self.implies(make_f(b), a):
                # a U b = F b when F b ⇒ a: F b holds at every position before the first b.
                return make_f(b)
            if kind == "W" and is_pure_eventuality(b) and self.implies(make_g(a), b):
                # a W b = (a U b) | G a = a U b when G a ⇒ b, and a U e = e.
                return b
        else:  # R, M
            if self.implies(b, a):
                return b
            if self.implies(b, negate(a)):
                return make_g(b) if kind == "R" else FALSE
            if isinstance(b, Binary) and b.kind == kind and self.implies(b.left, a):
                return b
            if isinstance(b, Disj) and a in b.args:
                # a R (a | b) = b W a and a M (a | b) = b U a (the duals).
                rest = make_or([x for x in b.args if x != a])
                return make_binary("W" if kind == "R" else "U", rest, a)
            if isinstance(b, Finally) and self.implies(b.arg, a):
                # a R F c = a M F c = F c when c ⇒ a: the first c releases (the duals of
                # the a U G c rule).
                return b
            if kind == "R" and isinstance(a, Finally) and self.implies(negate(a.arg), b):
                # F c R b = b when ¬c ⇒ b: F c releases at once, or G ¬c gives G b (F c M b
                # is F c & b already).
                return b
        return make_binary(kind, a, b)


def _assumed(item: Node, conjunction: bool) -> list[Node]:
    """The literals ``item`` makes true everywhere (``G ℓ``, ``G(ℓ1 & …)``: conjunction) or
    false everywhere unless it holds (``F ℓ``, ``F(ℓ1 | …)``: disjunction)."""
    if conjunction and isinstance(item, Always):
        parts = item.arg.args if isinstance(item.arg, Conj) else (item.arg,)
        return [p for p in parts if isinstance(p, Pos | Neg)]
    if not conjunction and isinstance(item, Finally):
        parts = item.arg.args if isinstance(item.arg, Disj) else (item.arg,)
        return [negate(p) for p in parts if isinstance(p, Pos | Neg)]
    return []


def _assume_literals(items: list[Node], conjunction: bool) -> list[Node]:
    """``x & G ℓ = x[ℓ := true] & G ℓ`` and ``x | F ℓ = x[ℓ := false] | F ℓ``: where the
    sibling does not already decide the junction, ℓ has that value at every position."""
    out = list(items)
    for index, item in enumerate(items):
        truths = _assumed(item, conjunction)
        if not truths:
            continue
        values: dict[Node, Node] = {}
        for literal in truths:
            values[literal] = TRUE
            values[negate(literal)] = FALSE
        out = [x if i == index else _substitute(x, values) for i, x in enumerate(out)]
    return out


def _substitute(f: Node, values: dict[Node, Node]) -> Node:
    match f:
        case Top() | Bottom():
            return f
        case Pos() | Neg():
            return values.get(f, f)
        case Conj(args=args):
            return make_and([_substitute(a, values) for a in args])
        case Disj(args=args):
            return make_or([_substitute(a, values) for a in args])
        case Finally(arg=arg):
            return make_f(_substitute(arg, values))
        case Always(arg=arg):
            return make_g(_substitute(arg, values))
        case Binary(kind=kind, left=left, right=right):
            return make_binary(kind, _substitute(left, values), _substitute(right, values))
        case _:
            assert_never(f)
