"""The translator's formula algebra: simplifying constructors, syntactic implication, and the
one-step expansion r(f) of Couvreur's construction, over the nodes of :mod:`tlmpc.automata.nnf`.

Conjunctions and disjunctions are built flattened, sorted and deduplicated, so equal formulas are
equal nodes and automaton states (conjunctions of formulas) deduplicate for free.

An expansion term (:class:`Expansion`) says how a formula can hold now: the letter must make
every proposition of ``pos`` true and of ``neg`` false, the run must satisfy the conjunction
``next`` from the next position on, and ``promises`` are the eventualities postponed on this
step.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from typing import NamedTuple, assert_never

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
from tlmpc.ltl.ast import (
    And,
    Const,
    Eventually,
    Formula,
    Globally,
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
    proposition_text,
)
from tlmpc.ltl.transform import nnf

__all__ = ["FALSE", "TRUE", "Expansion", "Node"]


class Expansion(NamedTuple):
    """One way to satisfy a formula now (see the module docstring)."""

    pos: frozenset[str]
    neg: frozenset[str]
    next: frozenset[Node]
    promises: frozenset[Node]


def _sorted(nodes: Iterable[Node]) -> tuple[Node, ...]:
    return tuple(sorted(nodes, key=repr))


def make_and(parts: Iterable[Node]) -> Node:
    """Flattened, sorted, deduplicated conjunction with constant folding."""
    flat: set[Node] = set()
    for part in parts:
        match part:
            case Bottom():
                return FALSE
            case Top():
                continue
            case Conj(args=args):
                flat.update(args)
            case _:
                flat.add(part)
    for part in flat:
        if isinstance(part, Pos) and neg(part.name) in flat:
            return FALSE
    strong = [
        part
        for part in flat
        if isinstance(part, Binary) and part.kind == "R" and Finally("F", part.left) in flat
    ]
    if strong:
        # F a & (a R b) = a M b (the dual rule).
        flat.difference_update(strong)
        flat.difference_update(
            Finally("F", part.left) for part in strong if isinstance(part, Binary)
        )
        flat.update(
            make_binary("M", part.left, part.right) for part in strong if isinstance(part, Binary)
        )
        return make_and(flat)
    always = [part for part in flat if isinstance(part, Always)]
    if len(always) > 1:
        # G a & G b = G(a & b): one obligation instead of many (fifty `avoid` phrases would
        # otherwise multiply into fifty conjuncts in every state).
        flat.difference_update(always)
        flat.add(Always("G", make_and(part.arg for part in always)))
    persistent = [
        part for part in flat if isinstance(part, Finally) and isinstance(part.arg, Always)
    ]
    if len(persistent) > 1:
        # F G a & F G b = F G(a & b)
        flat.difference_update(persistent)
        inner = make_and(part.arg.arg for part in persistent if isinstance(part.arg, Always))
        flat.add(Finally("F", Always("G", inner)))
    suspendable = [part for part in flat if _pure_eventuality(part) and _pure_universality(part)]
    # F a & s = s when s ⇒ F a (G F a & F a = G F a): dropped before the suspension below
    # would fold s into F a.
    flat.difference_update(
        [
            part
            for part in flat
            if isinstance(part, Finally)
            and part not in suspendable
            and any(implies(s, part) for s in suspendable)
        ]
    )
    eventual = sorted(
        (part for part in flat if isinstance(part, Finally) and part not in suspendable),
        key=repr,
    )
    if suspendable and eventual:
        # F a & F b & s = F(a & s) & F(b & s) for s both a pure eventuality and a pure
        # universality (its truth does not depend on the prefix): s is checked once the
        # last of a, b is reached, not all along.
        flat.difference_update(suspendable)
        flat.difference_update(eventual)
        flat.update(Finally("F", make_and([part.arg, *suspendable])) for part in eventual)
    if not flat:
        return TRUE
    if len(flat) == 1:
        return next(iter(flat))
    return Conj("&", _sorted(flat))


def make_or(parts: Iterable[Node]) -> Node:
    """Flattened, sorted, deduplicated disjunction with constant folding."""
    flat: set[Node] = set()
    for part in parts:
        match part:
            case Top():
                return TRUE
            case Bottom():
                continue
            case Disj(args=args):
                flat.update(args)
            case _:
                flat.add(part)
    for part in flat:
        if isinstance(part, Pos) and neg(part.name) in flat:
            return TRUE
    weak = [
        part
        for part in flat
        if isinstance(part, Binary) and part.kind == "U" and Always("G", part.left) in flat
    ]
    if weak:
        # G a | (a U b) = a W b (Spot's rule): one state instead of a choice.
        flat.difference_update(weak)
        flat.difference_update(Always("G", part.left) for part in weak if isinstance(part, Binary))
        flat.update(
            make_binary("W", part.left, part.right) for part in weak if isinstance(part, Binary)
        )
        return make_or(flat)
    recurrent = [
        part for part in flat if isinstance(part, Always) and isinstance(part.arg, Finally)
    ]
    if len(recurrent) > 1:
        # G F a | G F b = G F(a | b): one recurrence instead of a choice between them.
        flat.difference_update(recurrent)
        inner = make_or(part.arg.arg for part in recurrent if isinstance(part.arg, Finally))
        flat.add(Always("G", Finally("F", inner)))
    eventual = [part for part in flat if isinstance(part, Finally) or _pure_eventuality(part)]
    if len(eventual) > 1 and any(isinstance(part, Finally) for part in eventual):
        # F a | F b = F(a | b), and F a | e = F(a | e) for a pure eventuality e (= F e):
        # one eventuality, and the state loops instead of guessing a disjunct at once.
        flat.difference_update(eventual)
        flat.add(
            Finally(
                "F", make_or(part.arg if isinstance(part, Finally) else part for part in eventual)
            )
        )
    if not flat:
        return FALSE
    if len(flat) == 1:
        return next(iter(flat))
    return Disj("|", _sorted(flat))


def is_eventuality_free(f: Node) -> bool:
    """No U/F/M inside (then G/R over it need no acceptance condition)."""
    match f:
        case Top() | Bottom() | Pos() | Neg():
            return True
        case Conj(args=args) | Disj(args=args):
            return all(is_eventuality_free(a) for a in args)
        case Finally():
            return False
        case Always(arg=arg):
            return is_eventuality_free(arg)
        case Binary(kind=kind, left=left, right=right):
            return kind in ("R", "W") and is_eventuality_free(left) and is_eventuality_free(right)
        case _:
            assert_never(f)


def _pure_eventuality(f: Node) -> bool:
    """Formulas e with F e == e (Etessami–Holzmann): F x, x U (F...), GF..., ...

    Also ``x R e`` and ``e1 W e2`` (as Spot): a pure eventuality true at some position is
    true at every earlier one, so ``G e`` or ``e U (x & e)`` at a position, and ``G e1`` or
    ``e2`` at a position, carry over to every earlier position."""
    match f:
        case Finally():
            return True
        case Binary(kind="U" | "R", right=right):
            return _pure_eventuality(right)
        case Binary(kind="M" | "W", left=left, right=right):
            return _pure_eventuality(left) and _pure_eventuality(right)
        case Always(arg=arg):
            return _pure_eventuality(arg)
        case Conj(args=args) | Disj(args=args):
            return all(_pure_eventuality(a) for a in args)
        case Top() | Bottom() | Pos() | Neg() | Binary():
            return False
        case _:
            assert_never(f)


def _pure_universality(f: Node) -> bool:
    """Formulas u with G u == u: G x, x R (G...), FG..., ...; also ``x U u`` and
    ``u1 M u2`` (the duals of the extra pure eventualities)."""
    match f:
        case Always():
            return True
        case Binary(kind="R" | "U", right=right):
            return _pure_universality(right)
        case Binary(kind="W" | "M", left=left, right=right):
            return _pure_universality(left) and _pure_universality(right)
        case Finally(arg=arg):
            return _pure_universality(arg)
        case Conj(args=args) | Disj(args=args):
            return all(_pure_universality(a) for a in args)
        case Top() | Bottom() | Pos() | Neg() | Binary():
            return False
        case _:
            assert_never(f)


def is_pure_eventuality(f: Node) -> bool:
    """``F f == f`` (Etessami–Holzmann's pure eventualities)."""
    return _pure_eventuality(f)


def _suspendable(f: Node) -> bool:
    """Both a pure eventuality and a pure universality (``G F a``, ``F G a``): true at one
    position iff true at every position."""
    return _pure_eventuality(f) and _pure_universality(f)


def make_f(a: Node) -> Node:
    """F a, simplified: F true = true, F false = false, F(eventuality) = itself,
    F(a U b) = F b, F(a M b) = F(a & b), F(a | F b) = F(a | b)."""
    if a in (TRUE, FALSE) or _pure_eventuality(a):
        return a
    match a:
        case Binary(kind="U", right=right):
            return make_f(right)
        case Binary(kind="M", left=left, right=right):
            return make_f(make_and([left, right]))
        case Binary(kind="W", left=left, right=right):
            # F(a W b) = F(b | G a) (Spot's rule): no choice between two F's.
            return make_f(make_or([right, make_g(left)]))
        case Disj(args=args) if any(isinstance(x, Finally) for x in args):
            return make_f(make_or(x.arg if isinstance(x, Finally) else x for x in args))
    return Finally("F", a)


def make_g(a: Node) -> Node:
    """G a, simplified: G true = true, G(universality) = itself (conjunctions of G merge in
    :func:`make_and`), G(a R b) = G b, G(a W b) = G(a | b), G(a & G b) = G(a & b), and
    G F(a & e) = G F a & G e and G F(a R e) = G e for a pure eventuality e (which holds
    everywhere as soon as it holds infinitely often)."""
    if a in (TRUE, FALSE) or _pure_universality(a):
        return a
    match a:
        case Finally(arg=arg) if _pure_universality(arg):
            return a
        case Binary(kind="R", right=right):
            return make_g(right)
        case Binary(kind="W", left=left, right=right):
            return make_g(make_or([left, right]))
        case Conj(args=args) if any(isinstance(x, Always) for x in args):
            return make_g(make_and(x.arg if isinstance(x, Always) else x for x in args))
        case Disj(args=args) if sum(isinstance(x, Always) for x in args) == 1 and all(
            (isinstance(x, Always) and is_eventuality_free(x.arg)) or _pure_eventuality(x)
            for x in args
        ):
            # G(G a | e) = G(a W e) = G(a | e) for a pure eventuality e (for an eventuality-
            # free a: G a then costs no acceptance set, G(a | e) costs none more).
            return make_g(make_or(x.arg if isinstance(x, Always) else x for x in args))
        case Disj(args=args) if any(_suspendable(x) for x in args):
            # G(a | s) = G a | s for s both a pure eventuality and a pure universality (its
            # truth is the same at every position; Babiak et al.'s suspension).
            return make_or(
                [make_g(make_or(x for x in args if not _suspendable(x)))]
                + [x for x in args if _suspendable(x)]
            )
        case Finally(arg=Binary(kind="R", right=right)) if _pure_eventuality(right):
            # G F(a R e) = G e for a pure eventuality e: a R e implies e, and e infinitely
            # often is e everywhere, where a R e holds too.
            return make_g(right)
        case Finally(arg=Conj(args=args)) if any(_pure_eventuality(x) for x in args):
            eventual = [x for x in args if _pure_eventuality(x)]
            rest = [x for x in args if not _pure_eventuality(x)]
            return make_and([make_g(make_f(make_and(rest))), *(make_g(e) for e in eventual)])
    return Always("G", a)


def make_binary(kind: BinaryKind, a: Node, b: Node) -> Node:
    """a U/R/W/M b with the usual constant and idempotence rules."""
    if kind == "U":
        if b in (TRUE, FALSE) or a in (FALSE, b):
            return b
        if a == TRUE:
            return make_f(b)
        if _pure_eventuality(b):
            return b
        if isinstance(b, Binary) and b.kind == "U" and b.left == a:  # a U (a U b) = a U b
            return b
    elif kind == "R":
        if b in (TRUE, FALSE) or a in (TRUE, b):
            return b
        if a == FALSE:
            return make_g(b)
        if _pure_universality(b):
            return b
    elif kind == "W":
        if b == TRUE or a == TRUE:
            return TRUE
        if a in (FALSE, b):
            return b
        if b == FALSE:
            return make_g(a)
        if _pure_universality(a):
            return make_or([a, b])
        if _pure_eventuality(b) and (not _suspendable(b) or _suspendable(make_g(a))):
            # a W e = (a U e) | G a = e | G a (not for a suspendable e: the state of a W e
            # then loops on a, accepting; unless G a is suspendable too, as for a = F c).
            return make_or([b, make_g(a)])
    elif kind == "M":
        if b == FALSE or a == FALSE:
            return FALSE
        if b == TRUE or a == b:
            return make_f(a) if b == TRUE else a
        if a == TRUE:
            return b
        if _pure_eventuality(a):
            return make_and([a, b])
        if _pure_universality(b):  # a M u = (a R u) & F a = u & F a
            return make_and([b, make_f(a)])
    return Binary(kind, a, b)


def from_ast(formula: Formula) -> Node:
    """Translate an AST to the internal form (through NNF, with the rewriting rules)."""
    return _convert(nnf(formula))


_BINARY_KINDS: dict[type[Formula], BinaryKind] = {
    Until: "U",
    Release: "R",
    WeakUntil: "W",
    StrongRelease: "M",
}


def _convert(f: Formula) -> Node:
    if isinstance(f, Const):
        return TRUE if f.value else FALSE
    if isinstance(f, Prop):
        return pos(f.name)
    if isinstance(f, Not):
        assert isinstance(f.arg, Prop)
        return neg(f.arg.name)
    if isinstance(f, And):
        return make_and([_convert(a) for a in f.args])
    if isinstance(f, Or):
        return make_or([_convert(a) for a in f.args])
    if isinstance(f, Eventually):
        return make_f(_convert(f.arg))
    if isinstance(f, Globally):
        return make_g(_convert(f.arg))
    if isinstance(f, Until | Release | WeakUntil | StrongRelease):
        return make_binary(_BINARY_KINDS[type(f)], _convert(f.left), _convert(f.right))
    raise TypeError(f"unexpected node {f!r}")


def to_formula(f: Node) -> Formula:
    """The AST of an internal formula (for printing and for checking rewrites)."""
    match f:
        case Top():
            return Const(True)
        case Bottom():
            return Const(False)
        case Pos(name=name):
            return Prop(name)
        case Neg(name=name):
            return Not(Prop(name))
        case Conj(args=args):
            return And(tuple(to_formula(a) for a in args))
        case Disj(args=args):
            return Or(tuple(to_formula(a) for a in args))
        case Finally(arg=arg):
            return Eventually(to_formula(arg))
        case Always(arg=arg):
            return Globally(to_formula(arg))
        case Binary(kind="U", left=left, right=right):
            return Until(to_formula(left), to_formula(right))
        case Binary(kind="R", left=left, right=right):
            return Release(to_formula(left), to_formula(right))
        case Binary(kind="W", left=left, right=right):
            return WeakUntil(to_formula(left), to_formula(right))
        case Binary(kind="M", left=left, right=right):
            return StrongRelease(to_formula(left), to_formula(right))
        case Binary():
            raise AssertionError(f"unknown binary operator {f.kind!r}")
        case _:
            assert_never(f)


@functools.cache
def implies(f: Node, g: Node) -> bool:
    """A sound syntactic implication check f ⇒ g (incomplete; used to shrink states)."""
    if f in (g, FALSE) or g == TRUE:
        return True
    if isinstance(g, Conj):
        return all(implies(f, x) for x in g.args)
    if isinstance(f, Disj):
        return all(implies(x, g) for x in f.args)
    if isinstance(f, Conj) and any(implies(x, g) for x in f.args):
        return True
    if isinstance(g, Disj) and any(implies(f, x) for x in g.args):
        return True
    if isinstance(g, Finally) and implies(f, g.arg):
        return True
    if isinstance(f, Always) and implies(f.arg, g):
        return True
    if isinstance(f, Always) and isinstance(g, Always) and implies(f.arg, g.arg):
        return True
    if isinstance(f, Finally) and isinstance(g, Finally) and implies(f.arg, g.arg):
        return True
    if isinstance(g, Binary) and g.kind == "U" and implies(f, g.right):
        return True
    if (
        isinstance(g, Binary)
        and g.kind == "W"
        and (implies(f, g.right) or (isinstance(f, Always) and implies(f, g.left)))
    ):
        return True
    if not isinstance(f, Binary):
        return False
    if (
        f.kind == "U"
        and isinstance(g, Binary)
        and g.kind == "U"
        and implies(f.left, g.left)
        and implies(f.right, g.right)
    ):
        return True
    if f.kind == "U" and isinstance(g, Finally) and implies(f.right, g.arg):
        return True
    if f.kind == "R" and implies(f.right, g):
        return True
    return f.kind == "M" and implies(f.left, g) and implies(f.right, g)


@functools.lru_cache(maxsize=1 << 16)
def simplify_state(parts: frozenset[Node]) -> frozenset[Node] | None:
    """Drop conjuncts implied by others; None when the conjunction is false."""
    flat: set[Node] = set()
    for part in parts:
        match part:
            case Bottom():
                return None
            case Top():
                continue
            case Conj(args=args):
                flat.update(args)
            case _:
                flat.add(part)
    items = sorted(flat, key=repr)
    kept = []
    for index, item in enumerate(items):
        redundant = any(
            other != item and implies(other, item) and not (implies(item, other) and j > index)
            for j, other in enumerate(items)
        )
        if not redundant:
            kept.append(item)
    # (Not ``s & F(a & s) = F(a & s)`` for a suspendable ``s``, although the formulas are
    # equivalent: reaching ``a & s`` only postpones ``s`` into the next state, so with ``s``
    # dropped every cycle that keeps re-reaching ``a`` would accept without ``s`` ever being
    # fulfilled, e.g. ``p2 R (F(F G !p0 & !p1) | G(F p0 & p1))`` on ``(!p0 p0)^ω``.)
    return frozenset(kept)


#: The letters a translation is restricted to (each the set of propositions true at once), or
#: None.  Combining terms only adds literals, so a partial term that no letter allows can be
#: dropped as soon as it is formed: without this, ``G(F a_1 & ... & F a_n)`` over a map where
#: regions never overlap builds 2^n terms before the map's n + 1 letters rule all but a few out.
_LETTERS: list[frozenset[str]] | None = None


def cube_allowed(pos: frozenset[str], neg: frozenset[str]) -> bool:
    """Some letter of the current restriction makes ``pos`` true and ``neg`` false."""
    if pos & neg:
        return False
    if _LETTERS is None:
        return True
    return any(pos <= letter and not neg & letter for letter in _LETTERS)


def restrict_letters(letters: list[frozenset[str]] | None) -> list[frozenset[str]] | None:
    """Restrict the expansion to ``letters`` (None: every letter); returns the previous value.

    The expansion cache depends on the restriction, so it is cleared on every change."""
    global _LETTERS
    previous, _LETTERS = _LETTERS, letters
    if previous != letters:
        expand.cache_clear()
    return previous


#: At most this many expansion terms in one formula's or one state's expansion (each becomes
#: an edge of the automaton before reduction: see :data:`tlmpc.automata.translate.MAX_RAW_EDGES`).
MAX_TERMS = 100_000


class TooManyTerms(Exception):
    """An expansion would have more than ``limit`` (:data:`MAX_TERMS`) terms."""

    def __init__(self, limit: int) -> None:
        super().__init__(limit)
        self.limit = limit


def combine(left: Iterable[Expansion], right: Iterable[Expansion]) -> list[Expansion]:
    """Every pair of a ``left`` and a ``right`` term a letter allows, as one term: the union
    of their literals, obligations and promises (:class:`TooManyTerms` past
    :data:`MAX_TERMS` of them)."""
    out: list[Expansion] = []
    right = list(right)
    for lp, ln, lx, lprom in left:
        for rp, rn, rx, rprom in right:
            pos = lp | rp
            neg = ln | rn
            if not cube_allowed(pos, neg):
                continue
            out.append(Expansion(pos, neg, lx | rx, lprom | rprom))
        if len(out) > MAX_TERMS:
            raise TooManyTerms(MAX_TERMS)
    return out


_NO_NAMES: frozenset[str] = frozenset()
_NO_NODES: frozenset[Node] = frozenset()
_NOTHING = Expansion(_NO_NAMES, _NO_NAMES, _NO_NODES, _NO_NODES)


def _unless(terms: Iterable[Expansion], alternatives: Iterable[Node]) -> list[Expansion]:
    """``terms`` restricted to the letters where the literal ``alternatives`` are false.

    Sound whenever a literal alternative's own term (that literal, nothing else) is also
    among the expansion terms: it dominates every restricted-away letter.  Non-literal
    alternatives are ignored."""
    alternatives = list(alternatives)
    must = frozenset(x.name for x in alternatives if isinstance(x, Neg))
    must_not = frozenset(x.name for x in alternatives if isinstance(x, Pos))
    if not must and not must_not:
        return list(terms)
    return [
        Expansion(p | must, n | must_not, x, pr)
        for p, n, x, pr in terms
        if cube_allowed(p | must, n | must_not)
    ]


def _literal(f: Node) -> bool:
    return isinstance(f, Pos | Neg)


@functools.cache
def expand(f: Node) -> tuple[Expansion, ...]:
    """r(f): the ways to satisfy ``f`` now, as expansion terms."""
    later = Expansion(_NO_NAMES, _NO_NAMES, frozenset([f]), _NO_NODES)
    promise = Expansion(_NO_NAMES, _NO_NAMES, frozenset([f]), frozenset([f]))
    match f:
        case Top():
            return (_NOTHING,)
        case Bottom():
            return ()
        case Pos(name=name):
            return (Expansion(frozenset([name]), _NO_NAMES, _NO_NODES, _NO_NODES),)
        case Neg(name=name):
            return (Expansion(_NO_NAMES, frozenset([name]), _NO_NODES, _NO_NODES),)
        case Conj(args=args):
            result = [_NOTHING]
            for arg in args:
                result = combine(result, expand(arg))
            return tuple(result)
        case Disj(args=args):
            # Literal disjuncts make the other disjuncts' terms exclusive: where a literal
            # holds, its own term (no obligation, no promise) dominates theirs.
            literals = [arg for arg in args if _literal(arg)]
            others = [t for arg in args if not _literal(arg) for t in expand(arg)]
            return (*(t for arg in literals for t in expand(arg)), *_unless(others, literals))
        case Finally(arg=arg):  # b | (!b & P & N(F b)) -- `!b` only when b is a literal
            return (*expand(arg), *_unless([promise], [arg]))
        case Always(arg=arg):  # a & N(G a)
            return tuple(combine(expand(arg), [later]))
        case Binary(kind="U", left=a, right=b):  # b | (a & P & N(a U b))
            return (*expand(b), *_unless(combine(expand(a), [promise]), [b]))
        case Binary(kind="M", left=a, right=b):  # (a & b) | (b & P & N(a M b))
            return (
                *combine(expand(a), expand(b)),
                *_unless(combine(expand(b), [promise]), [a]),
            )
        case Binary(kind="R", left=a, right=b):  # (a & b) | (b & N(a R b))
            return (
                *combine(expand(a), expand(b)),
                *_unless(combine(expand(b), [later]), [a]),
            )
        case Binary(kind="W", left=a, right=b):  # b | (a & N(a W b))
            return (*expand(b), *_unless(combine(expand(a), [later]), [b]))
        case Binary():
            raise ValueError(f"unknown binary operator {f.kind!r}")
        case _:
            assert_never(f)


def eventualities(f: Node) -> list[Node]:
    """Every U/F/M subformula of ``f`` (one acceptance set each), in a stable order."""
    found: dict[Node, None] = {}
    stack = [f]
    while stack:
        g = stack.pop()
        match g:
            case Finally(arg=arg):
                found.setdefault(g, None)
                stack.append(arg)
            case Binary(kind=kind, left=left, right=right):
                if kind in ("U", "M"):
                    found.setdefault(g, None)
                stack.extend((left, right))
            case Conj(args=args) | Disj(args=args):
                stack.extend(args)
            case Always(arg=arg):
                stack.append(arg)
            case Top() | Bottom() | Pos() | Neg():
                pass
            case _:
                assert_never(g)
    return sorted(found, key=repr)


def props(f: Node) -> frozenset[str]:
    """The propositions that occur in ``f``."""
    match f:
        case Top() | Bottom():
            return frozenset()
        case Pos(name=name) | Neg(name=name):
            return frozenset([name])
        case Conj(args=args) | Disj(args=args):
            return frozenset().union(*(props(a) for a in args))
        case Finally(arg=arg) | Always(arg=arg):
            return props(arg)
        case Binary(left=left, right=right):
            return props(left) | props(right)
        case _:
            assert_never(f)


def to_text(f: Node) -> str:
    """Readable form of an internal formula (state names), which the LTL reader reads back:
    names are written as :func:`~tlmpc.ltl.ast.proposition_text` writes them (``"true"``,
    ``"a b"``, ``""`` quoted)."""
    match f:
        case Top():
            return "true"
        case Bottom():
            return "false"
        case Pos(name=name):
            return proposition_text(name)
        case Neg(name=name):
            return "!" + proposition_text(name)
        case Conj(args=args):
            return "(" + " & ".join(to_text(a) for a in args) + ")"
        case Disj(args=args):
            return "(" + " | ".join(to_text(a) for a in args) + ")"
        case Finally(arg=arg):
            return f"F {to_text(arg)}"
        case Always(arg=arg):
            return f"G {to_text(arg)}"
        case Binary(kind=kind, left=left, right=right):
            return f"({to_text(left)} {kind} {to_text(right)})"
        case _:
            assert_never(f)
