"""The translator's internal formulas: hash-consed NNF tuples, syntactic implication, and the
one-step expansion r(f) of Couvreur's construction.

A formula is a tuple: ``("t",)``, ``("f",)``, ``("p", name)``, ``("n", name)`` (negated
proposition), ``("&", args)``/``("|", args)`` with ``args`` a sorted tuple of distinct
formulas, ``("U"|"R"|"W"|"M", a, b)``, ``("F", a)``, ``("G", a)``.  Equal formulas are equal
tuples, so automaton states (conjunctions of formulas) deduplicate for free.

An expansion term is ``(pos, neg, next, promises)``: the letter must make every proposition of
``pos`` true and of ``neg`` false, the run must satisfy the conjunction ``next`` from the next
position on, and ``promises`` are the eventualities postponed on this step.
"""

from __future__ import annotations

import functools
from typing import Any

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
)
from tlmpc.ltl.transform import nnf

T = Any  # an internal formula tuple
TRUE: T = ("t",)
FALSE: T = ("f",)
Term = tuple[frozenset[str], frozenset[str], frozenset[T], frozenset[T]]


def make_and(parts: list[T] | tuple[T, ...]) -> T:
    """Flattened, sorted, deduplicated conjunction with constant folding."""
    flat: set[T] = set()
    for part in parts:
        if part == FALSE:
            return FALSE
        if part == TRUE:
            continue
        if part[0] == "&":
            flat.update(part[1])
        else:
            flat.add(part)
    for part in flat:
        if part[0] == "p" and ("n", part[1]) in flat:
            return FALSE
    always = [part for part in flat if part[0] == "G"]
    if len(always) > 1:
        # G a & G b = G(a & b): one obligation instead of many (fifty `avoid` phrases would
        # otherwise multiply into fifty conjuncts in every state).
        flat.difference_update(always)
        flat.add(("G", make_and([part[1] for part in always])))
    persistent = [part for part in flat if part[0] == "F" and part[1][0] == "G"]
    if len(persistent) > 1:
        # F G a & F G b = F G(a & b)
        flat.difference_update(persistent)
        flat.add(("F", ("G", make_and([part[1][1] for part in persistent]))))
    suspendable = [part for part in flat if _pure_eventuality(part) and _pure_universality(part)]
    eventual = sorted(
        (part for part in flat if part[0] == "F" and part not in suspendable), key=repr
    )
    if suspendable and eventual:
        # F a & F b & s = F(a & s) & F(b & s) for s both a pure eventuality and a pure
        # universality (its truth does not depend on the prefix): s is checked once the
        # last of a, b is reached, not all along.
        flat.difference_update(suspendable)
        flat.difference_update(eventual)
        flat.update(("F", make_and([part[1], *suspendable])) for part in eventual)
    if not flat:
        return TRUE
    if len(flat) == 1:
        return next(iter(flat))
    return ("&", tuple(sorted(flat, key=repr)))


def make_or(parts: list[T] | tuple[T, ...]) -> T:
    """Flattened, sorted, deduplicated disjunction with constant folding."""
    flat: set[T] = set()
    for part in parts:
        if part == TRUE:
            return TRUE
        if part == FALSE:
            continue
        if part[0] == "|":
            flat.update(part[1])
        else:
            flat.add(part)
    for part in flat:
        if part[0] == "p" and ("n", part[1]) in flat:
            return TRUE
    recurrent = [part for part in flat if part[0] == "G" and part[1][0] == "F"]
    if len(recurrent) > 1:
        # G F a | G F b = G F(a | b): one recurrence instead of a choice between them.
        flat.difference_update(recurrent)
        flat.add(("G", ("F", make_or([part[1][1] for part in recurrent]))))
    eventual = [part for part in flat if part[0] == "F" or _pure_eventuality(part)]
    if len(eventual) > 1 and any(part[0] == "F" for part in eventual):
        # F a | F b = F(a | b), and F a | e = F(a | e) for a pure eventuality e (= F e):
        # one eventuality, and the state loops instead of guessing a disjunct at once.
        flat.difference_update(eventual)
        flat.add(("F", make_or([part[1] if part[0] == "F" else part for part in eventual])))
    if not flat:
        return FALSE
    if len(flat) == 1:
        return next(iter(flat))
    return ("|", tuple(sorted(flat, key=repr)))


def is_eventuality_free(f: T) -> bool:
    """No U/F/M inside (then G/R over it need no acceptance condition)."""
    kind = f[0]
    if kind in ("U", "F", "M"):
        return False
    if kind in ("&", "|"):
        return all(is_eventuality_free(a) for a in f[1])
    if kind in ("R", "W"):
        return is_eventuality_free(f[1]) and is_eventuality_free(f[2])
    if kind == "G":
        return is_eventuality_free(f[1])
    return True


def _pure_eventuality(f: T) -> bool:
    """Formulas e with F e == e (Etessami–Holzmann): F x, x U (F...), GF..., ..."""
    kind = f[0]
    if kind == "F":
        return True
    if kind == "U":
        return _pure_eventuality(f[2])
    if kind == "M":
        return _pure_eventuality(f[1]) and _pure_eventuality(f[2])
    if kind == "G":
        return _pure_eventuality(f[1])
    if kind in ("&", "|"):
        return all(_pure_eventuality(a) for a in f[1])
    return False


def _pure_universality(f: T) -> bool:
    """Formulas u with G u == u: G x, x R (G...), FG..., ..."""
    kind = f[0]
    if kind == "G":
        return True
    if kind == "R":
        return _pure_universality(f[2])
    if kind == "W":
        return _pure_universality(f[1]) and _pure_universality(f[2])
    if kind == "F":
        return _pure_universality(f[1])
    if kind in ("&", "|"):
        return all(_pure_universality(a) for a in f[1])
    return False


def make_f(a: T) -> T:
    """F a, simplified: F true = true, F false = false, F(eventuality) = itself,
    F(a U b) = F b, F(a M b) = F(a & b), F(a | F b) = F(a | b)."""
    if a in (TRUE, FALSE) or _pure_eventuality(a):
        return a
    if a[0] == "U":
        return make_f(a[2])
    if a[0] == "M":
        return make_f(make_and([a[1], a[2]]))
    if a[0] == "|" and any(x[0] == "F" for x in a[1]):
        return make_f(make_or([x[1] if x[0] == "F" else x for x in a[1]]))
    return ("F", a)


def make_g(a: T) -> T:
    """G a, simplified: G true = true, G(universality) = itself (conjunctions of G merge in
    :func:`make_and`), G(a R b) = G b, G(a W b) = G(a | b), G(a & G b) = G(a & b), and
    G F(a & e) = G F a & G e for a pure eventuality e (which holds everywhere as soon as it
    holds infinitely often)."""
    if a in (TRUE, FALSE) or _pure_universality(a):
        return a
    if a[0] == "F" and _pure_universality(a[1]):
        return a
    if a[0] == "R":
        return make_g(a[2])
    if a[0] == "W":
        return make_g(make_or([a[1], a[2]]))
    if a[0] == "&" and any(x[0] == "G" for x in a[1]):
        return make_g(make_and([x[1] if x[0] == "G" else x for x in a[1]]))
    if a[0] == "F" and a[1][0] == "&":
        eventual = [x for x in a[1][1] if _pure_eventuality(x)]
        if eventual:
            rest = [x for x in a[1][1] if not _pure_eventuality(x)]
            return make_and([make_g(make_f(make_and(rest))), *(make_g(e) for e in eventual)])
    return ("G", a)


def make_binary(kind: str, a: T, b: T) -> T:
    """a U/R/W/M b with the usual constant and idempotence rules."""
    if kind == "U":
        if b in (TRUE, FALSE) or a in (FALSE, b):
            return b
        if a == TRUE:
            return make_f(b)
        if _pure_eventuality(b):
            return b
        if b[0] == "U" and b[1] == a:  # a U (a U b) = a U b
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
        if _pure_eventuality(b):  # a W e = (a U e) | G a = e | G a
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
    return (kind, a, b)


def from_ast(formula: Formula) -> T:
    """Translate an AST to the internal form (through NNF, with the rewriting rules)."""
    return _convert(nnf(formula))


def _convert(f: Formula) -> T:
    if isinstance(f, Const):
        return TRUE if f.value else FALSE
    if isinstance(f, Prop):
        return ("p", f.name)
    if isinstance(f, Not):
        assert isinstance(f.arg, Prop)
        return ("n", f.arg.name)
    if isinstance(f, And):
        return make_and([_convert(a) for a in f.args])
    if isinstance(f, Or):
        return make_or([_convert(a) for a in f.args])
    if isinstance(f, Eventually):
        return make_f(_convert(f.arg))
    if isinstance(f, Globally):
        return make_g(_convert(f.arg))
    if isinstance(f, Until | Release | WeakUntil | StrongRelease):
        kind = {Until: "U", Release: "R", WeakUntil: "W", StrongRelease: "M"}[type(f)]
        return make_binary(kind, _convert(f.left), _convert(f.right))
    raise TypeError(f"unexpected node {f!r}")


def to_formula(f: T) -> Formula:
    """The AST of an internal formula (for printing and for checking rewrites)."""
    kind = f[0]
    if kind in ("t", "f"):
        return Const(kind == "t")
    if kind == "p":
        return Prop(f[1])
    if kind == "n":
        return Not(Prop(f[1]))
    if kind in ("&", "|"):
        args = tuple(to_formula(a) for a in f[1])
        return And(args) if kind == "&" else Or(args)
    if kind == "F":
        return Eventually(to_formula(f[1]))
    if kind == "G":
        return Globally(to_formula(f[1]))
    node = {"U": Until, "R": Release, "W": WeakUntil, "M": StrongRelease}[kind]
    return node(to_formula(f[1]), to_formula(f[2]))


@functools.cache
def implies(f: T, g: T) -> bool:
    """A sound syntactic implication check f ⇒ g (incomplete; used to shrink states)."""
    if f in (g, FALSE) or g == TRUE:
        return True
    fk, gk = f[0], g[0]
    if gk == "&":
        return all(implies(f, x) for x in g[1])
    if fk == "|":
        return all(implies(x, g) for x in f[1])
    if fk == "&" and any(implies(x, g) for x in f[1]):
        return True
    if gk == "|" and any(implies(f, x) for x in g[1]):
        return True
    if gk == "F" and implies(f, g[1]):
        return True
    if fk == "G" and implies(f[1], g):
        return True
    if fk == "G" and gk == "G" and implies(f[1], g[1]):
        return True
    if fk == "F" and gk == "F" and implies(f[1], g[1]):
        return True
    if gk == "U" and implies(f, g[2]):
        return True
    if gk == "W" and (implies(f, g[2]) or (implies(f, g[1]) and fk == "G")):
        return True
    if fk == "U" and gk == "U" and implies(f[1], g[1]) and implies(f[2], g[2]):
        return True
    if fk == "U" and gk == "F" and implies(f[2], g[1]):
        return True
    if fk == "R" and implies(f[2], g):
        return True
    return bool(fk == "M" and implies(f[1], g) and implies(f[2], g))


@functools.lru_cache(maxsize=1 << 16)
def simplify_state(parts: frozenset[T]) -> frozenset[T] | None:
    """Drop conjuncts implied by others; None when the conjunction is false."""
    flat: set[T] = set()
    for part in parts:
        if part == FALSE:
            return None
        if part == TRUE:
            continue
        if part[0] == "&":
            flat.update(part[1])
        else:
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


def _combine(left: list[Term], right: list[Term]) -> list[Term]:
    out: list[Term] = []
    for lp, ln, lx, lprom in left:
        for rp, rn, rx, rprom in right:
            pos = lp | rp
            neg = ln | rn
            if not cube_allowed(pos, neg):
                continue
            out.append((pos, neg, lx | rx, lprom | rprom))
    return out


_EMPTY: frozenset[Any] = frozenset()


def _unless(terms: list[Term] | tuple[Term, ...], alternatives: list[T]) -> list[Term]:
    """``terms`` restricted to the letters where the literal ``alternatives`` are false.

    Sound whenever a literal alternative's own term (that literal, nothing else) is also
    among the expansion terms: it dominates every restricted-away letter.  Non-literal
    alternatives are ignored."""
    pos = frozenset(x[1] for x in alternatives if x[0] == "n")
    neg = frozenset(x[1] for x in alternatives if x[0] == "p")
    if not pos and not neg:
        return list(terms)
    return [(p | pos, n | neg, x, pr) for p, n, x, pr in terms if cube_allowed(p | pos, n | neg)]


@functools.cache
def expand(f: T) -> tuple[Term, ...]:
    """r(f): the ways to satisfy ``f`` now, as expansion terms."""
    kind = f[0]
    if kind == "t":
        return ((_EMPTY, _EMPTY, _EMPTY, _EMPTY),)
    if kind == "f":
        return ()
    if kind == "p":
        return ((frozenset([f[1]]), _EMPTY, _EMPTY, _EMPTY),)
    if kind == "n":
        return ((_EMPTY, frozenset([f[1]]), _EMPTY, _EMPTY),)
    if kind == "&":
        result: list[Term] = [(_EMPTY, _EMPTY, _EMPTY, _EMPTY)]
        for arg in f[1]:
            result = _combine(result, list(expand(arg)))
        return tuple(result)
    if kind == "|":
        # Literal disjuncts make the other disjuncts' terms exclusive: where a literal holds,
        # its own term (no obligation, no promise) dominates theirs.
        literals = [arg for arg in f[1] if arg[0] in ("p", "n")]
        others = [t for arg in f[1] if arg[0] not in ("p", "n") for t in expand(arg)]
        return (
            *(t for arg in literals for t in expand(arg)),
            *_unless(others, literals),
        )
    later: Term = (_EMPTY, _EMPTY, frozenset([f]), _EMPTY)
    promise: Term = (_EMPTY, _EMPTY, frozenset([f]), frozenset([f]))
    if kind == "F":  # b | (!b & P & N(F b)) -- `!b` only when b is a literal
        return (*expand(f[1]), *_unless([promise], [f[1]]))
    if kind == "G":  # a & N(G a)
        return tuple(_combine(list(expand(f[1])), [later]))
    a, b = f[1], f[2]
    if kind == "U":  # b | (a & P & N(a U b))
        return (*expand(b), *_unless(_combine(list(expand(a)), [promise]), [b]))
    if kind == "M":  # (a & b) | (b & P & N(a M b))
        return (
            *_combine(list(expand(a)), list(expand(b))),
            *_unless(_combine(list(expand(b)), [promise]), [a]),
        )
    if kind == "R":  # (a & b) | (b & N(a R b))
        return (
            *_combine(list(expand(a)), list(expand(b))),
            *_unless(_combine(list(expand(b)), [later]), [a]),
        )
    if kind == "W":  # b | (a & N(a W b))
        return (*expand(b), *_unless(_combine(list(expand(a)), [later]), [b]))
    raise ValueError(f"unknown formula kind {kind!r}")


def eventualities(f: T) -> list[T]:
    """Every U/F/M subformula of ``f`` (one acceptance set each), in a stable order."""
    found: dict[T, None] = {}
    stack = [f]
    while stack:
        g = stack.pop()
        kind = g[0]
        if kind in ("U", "F", "M"):
            found.setdefault(g, None)
        if kind in ("&", "|"):
            stack.extend(g[1])
        elif kind in ("U", "R", "W", "M"):
            stack.extend((g[1], g[2]))
        elif kind in ("F", "G"):
            stack.append(g[1])
    return sorted(found, key=repr)


def to_text(f: T) -> str:
    """Readable form of an internal formula (state names)."""
    kind = f[0]
    if kind == "t":
        return "true"
    if kind == "f":
        return "false"
    if kind == "p":
        return str(f[1])
    if kind == "n":
        return "!" + str(f[1])
    if kind in ("&", "|"):
        return "(" + f" {kind} ".join(to_text(a) for a in f[1]) + ")"
    if kind in ("F", "G"):
        return f"{kind} {to_text(f[1])}"
    return f"({to_text(f[1])} {kind} {to_text(f[2])})"
