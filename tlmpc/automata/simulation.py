"""Direct- and reverse-simulation reduction of a TGBA (Spot's ``simulation`` and
``cosimulation``; Somenzi–Bloem "little brothers").

State ``q`` directly simulates ``p`` when every edge ``p --a/M--> p'`` is matched, for the same
letter ``a``, by an edge ``q --a/M'--> q'`` with ``M ⊆ M'`` and ``q'`` simulating ``p'``.  The
largest such relation is computed by fixpoint refinement over explicit letter sets (bitmasks over
the 2^|AP| valuations, or over the map's letters when the translation is restricted to them).
Two language-preserving reductions follow (Etessami–Wilke–Schuller; Clemente–Mayr):

* **quotient** by simulation equivalence (states simulating each other are merged);
* **pruning**: a cube of an edge is dropped when, for each of its letters, another edge of the
  same source goes to a strictly better target with at least its marks.

The reverse simulation is the direct simulation of the transposed automaton in which only the
initial state reverse-simulates the initial state (:func:`cosimulation`); its quotient merges
states with the same pasts and its pruning drops edges into a state that a strictly better
source also provides (:func:`quotient_reverse`, :func:`prune_reverse`).

The relation is computed on bitsets: the letters are split into the atoms of the edges' letter
sets, and the states matching an edge on an atom come from precomputed predecessor masks.

Edges that lie on no cycle are taken at most once by a run, so their marks do not matter; they
are given every mark first ("saturation"), which lets them dominate and be dominated more often.

Every step charges its work to a budget (:mod:`tlmpc.automata.work`, about one unit per edge
visited); when it runs out, the automaton reduced so far (always correct) is returned.
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict
from collections.abc import Sequence

from tlmpc.automata import work
from tlmpc.automata.cover import cover_formula
from tlmpc.automata.model import Automaton, Edge
from tlmpc.ltl.ast import And, Const, Formula, Not, Or, Prop, disjoin

#: Above this many propositions the full alphabet is too large to enumerate; no reduction.
MAX_APS = 14


class Alphabet:
    """Letter bitmasks of guards, over explicit letters or all valuations of ``aps``."""

    def __init__(self, aps: Sequence[str], letters: Sequence[frozenset[str]] | None) -> None:
        self.literal: dict[str, int] = {}
        self.aps = tuple(aps)
        # The valuation (numbered as in :mod:`tlmpc.automata.cover`) of each explicit letter.
        self.valuations: tuple[int, ...] | None = None
        if letters is not None and len(aps) <= MAX_APS:
            self.valuations = tuple(
                sum(1 << i for i, ap in enumerate(aps) if ap in letter) for letter in letters
            )
        if letters is None:
            n = len(aps)
            size = 1 << n
            self.full = (1 << size) - 1
            for i, ap in enumerate(aps):
                mask = 0
                for valuation in range(size):
                    if valuation >> i & 1:
                        mask |= 1 << valuation
                self.literal[ap] = mask
        else:
            self.full = (1 << len(letters)) - 1
            for ap in aps:
                mask = 0
                for i, letter in enumerate(letters):
                    if ap in letter:
                        mask |= 1 << i
                self.literal[ap] = mask
        self._cache: dict[Formula, int] = {}

    def mask(self, guard: Formula) -> int:
        """The letters that enable ``guard``."""
        cached = self._cache.get(guard)
        if cached is not None:
            return cached
        if isinstance(guard, Const):
            result = self.full if guard.value else 0
        elif isinstance(guard, Prop):
            result = self.literal.get(guard.name, 0)
        elif isinstance(guard, Not):
            result = self.full & ~self.mask(guard.arg)
        elif isinstance(guard, And):
            result = self.full
            for arg in guard.args:
                result &= self.mask(arg)
        elif isinstance(guard, Or):
            result = 0
            for arg in guard.args:
                result |= self.mask(arg)
        else:
            raise ValueError(f"guards are propositional, got {guard!r}")
        self._cache[guard] = result
        return result

    def guard(self, mask: int) -> Formula | None:
        """A guard enabled by exactly the letters of ``mask`` (None over explicit letters of
        more than :data:`MAX_APS` propositions)."""
        if self.valuations is None:
            if len(self.aps) > MAX_APS:
                return None
            return cover_formula(self.aps, mask, mask)
        lower = 0
        for index, valuation in enumerate(self.valuations):
            if mask >> index & 1:
                lower |= 1 << valuation
        others = (1 << (1 << len(self.aps))) - 1
        for valuation in self.valuations:
            others &= ~(1 << valuation)
        # Valuations that are no letter may go either way (no run reads them).
        return cover_formula(self.aps, lower, lower | others)


def _bits(marks: frozenset[int]) -> int:
    value = 0
    for mark in marks:
        value |= 1 << mark
    return value


def saturate(automaton: Automaton, component: Sequence[int]) -> Automaton:
    """Give every mark to edges between SCCs (taken at most once, so the language stays)."""
    everything = frozenset(range(automaton.num_acc))
    edges = tuple(
        e
        if component[e.src] == component[e.dst]
        else Edge(src=e.src, dst=e.dst, guard=e.guard, marks=everything)
        for e in automaton.edges
    )
    return _with_edges(automaton, edges)


def strip_transient(automaton: Automaton, component: Sequence[int]) -> Automaton:
    """Take every mark off edges between SCCs (taken at most once, so the language stays)."""
    edges = tuple(
        e
        if component[e.src] == component[e.dst] or not e.marks
        else Edge(src=e.src, dst=e.dst, guard=e.guard, marks=frozenset())
        for e in automaton.edges
    )
    return _with_edges(automaton, edges)


def _with_edges(automaton: Automaton, edges: Sequence[Edge]) -> Automaton:
    return dataclasses.replace(automaton, edges=tuple(edges))


def transpose(automaton: Automaton) -> Automaton:
    """Every edge reversed (same guard and marks): the reverse simulation of an automaton is
    the direct simulation of its transpose, with the initial state told apart."""
    edges = tuple(Edge(src=e.dst, dst=e.src, guard=e.guard, marks=e.marks) for e in automaton.edges)
    return _with_edges(automaton, edges)


def cosimulation(automaton: Automaton, alphabet: Alphabet, deadline: float) -> list[list[bool]]:
    """``cosim[p][q]``: ``q`` reverse-simulates ``p`` (Spot's ``cosimulation``).

    The largest relation where ``p`` initial implies ``q`` initial and every edge
    ``p' --a/M--> p`` is matched by an edge ``q' --a/M'--> q`` with ``M ⊆ M'`` and ``q'``
    reverse-simulating ``p'``: every run prefix reaching ``p`` is matched, position by
    position and with at least its marks, by a prefix reaching ``q``.  König's lemma turns
    infinitely many such replacements into one run, so merging reverse-simulation-equivalent
    states and dropping reverse little brothers (:func:`prune_reverse`) keep the language."""
    return simulation(transpose(automaton), alphabet, deadline, initial=automaton.initial)


def quotient_reverse(automaton: Automaton, cosim: list[list[bool]]) -> Automaton:
    """Merge states that reverse-simulate each other: edges into a merged state go to its
    representative, and the representative gets the edges out of every merged state."""
    n = automaton.num_states
    representative = list(range(n))
    for p in range(n):
        for q in range(p):
            if representative[q] == q and cosim[p][q] and cosim[q][p]:
                representative[p] = q
                break
    if all(representative[p] == p for p in range(n)):
        return automaton
    edges = tuple(
        Edge(src=representative[e.src], dst=representative[e.dst], guard=e.guard, marks=e.marks)
        for e in automaton.edges
    )
    return dataclasses.replace(automaton, edges=edges, initial=representative[automaton.initial])


def prune_reverse(
    automaton: Automaton, alphabet: Alphabet, cosim: list[list[bool]], deadline: float
) -> Automaton:
    """Drop the cubes of an edge into ``p`` whose every letter also enters ``p`` from a
    strictly better source (reverse little brothers) with at least its marks."""
    return transpose(prune(transpose(automaton), alphabet, cosim, deadline))


def simulation(
    automaton: Automaton,
    alphabet: Alphabet,
    deadline: float,
    component: Sequence[int] | None = None,
    *,
    initial: int | None = None,
) -> list[list[bool]]:
    """``sim[p][q]``: ``q`` directly simulates ``p`` (largest relation).

    With ``component`` (the SCC of every state), the matching edge's marks do not matter when
    that edge lies between SCCs (the simulating run takes such edges finitely often, so every
    mark the simulated run sees infinitely often it still sees infinitely often): the relation
    then only implies language inclusion, which is all :func:`merge_transient` needs; it is
    not a direct simulation, so :func:`quotient` and :func:`prune` must not use it."""
    n = automaton.num_states
    out: list[list[tuple[int, int, int]]] = [[] for _ in range(n)]
    every = (1 << automaton.num_acc) - 1
    work.charge(deadline, n + len(automaton.edges))
    for e in automaton.edges:
        out[e.src].append((alphabet.mask(e.guard), _bits(e.marks), e.dst))
    answers = out
    if component is not None:
        answers = [[] for _ in range(n)]
        for e in automaton.edges:
            transient = component[e.src] != component[e.dst]
            marks = every if transient else _bits(e.marks)
            answers[e.src].append((alphabet.mask(e.guard), marks, e.dst))
    # Letters a state enables at all: a necessary condition, checked first.
    enabled = [0] * n
    for state in range(n):
        for letters, _marks, _dst in out[state]:
            enabled[state] |= letters
    # simulators[p]: bitmask of the states still believed to simulate p.
    work.charge(deadline, n * n)
    simulators = [0] * n
    for p in range(n):
        for q in range(n):
            if (enabled[p] & ~enabled[q]) == 0:
                simulators[p] |= 1 << q
    if initial is not None:
        # Only the initial state matches the empty prefix that reaches the initial state.
        simulators[initial] = 1 << initial
    # Letters every edge treats alike (the atoms of the algebra of the edges' letter sets):
    # a state matches an edge on every letter iff it does on one letter of every atom.
    atoms = [alphabet.full]
    for letters in {
        letters for edges in (out, answers) for row in edges for letters, _m, _d in row
    }:
        work.charge(deadline, len(atoms))
        split = []
        for atom in atoms:
            inside = atom & letters
            if inside and inside != atom:
                split += [inside, atom & ~letters]
            else:
                split.append(atom)
        atoms = split
    atom_ids = {
        letters: [i for i, atom in enumerate(atoms) if atom & letters]
        for letters in {letters for row in out for letters, _m, _d in row}
    }
    needed_marks = {marks for row in out for _l, marks, _d in row}
    # pre[(atom, marks)][d]: bitmask of the states with an edge to d on that atom carrying at
    # least those marks.
    pre: dict[tuple[int, int], list[int]] = {}
    for q in range(n):
        work.charge(deadline, len(answers[q]) * len(atoms) * len(needed_marks))
        for letters, other_marks, target in answers[q]:
            for index, atom in enumerate(atoms):
                if not atom & letters:
                    continue
                for marks in needed_marks:
                    if marks & ~other_marks == 0:
                        row = pre.get((index, marks))
                        if row is None:
                            row = pre[(index, marks)] = [0] * n
                        row[target] |= 1 << q
    changed = True
    while changed:
        changed = False
        work.charge(deadline)
        # Predecessors (on an atom, with marks) of the simulators of a target, this sweep.
        memo: dict[tuple[int, int, int], int] = {}
        for p in range(n):
            current = simulators[p]
            if current == 1 << p:
                continue
            work.charge(deadline, 1 + len(out[p]))
            for letters, marks, target in out[p]:
                good = simulators[target]
                for index in atom_ids[letters]:
                    key = (index, marks, target)
                    matched = memo.get(key)
                    if matched is None:
                        matched = 0
                        row = pre.get((index, marks))
                        if row is not None:
                            work.charge(deadline, good.bit_count())  # the loop below
                            rest = good
                            while rest:
                                low = rest & -rest
                                matched |= row[low.bit_length() - 1]
                                rest ^= low
                        memo[key] = matched
                    current &= matched | (1 << p)
                    if current == 1 << p:
                        break
                if current == 1 << p:
                    break
            if current != simulators[p]:
                simulators[p] = current
                changed = True
    work.charge(deadline, n * n)
    return [[q == p or bool(simulators[p] >> q & 1) for q in range(n)] for p in range(n)]


def quotient(automaton: Automaton, sim: list[list[bool]]) -> Automaton:
    """Merge states that simulate each other (edges keep their guards and marks)."""
    n = automaton.num_states
    representative = list(range(n))
    for p in range(n):
        for q in range(p):
            if representative[q] == q and sim[p][q] and sim[q][p]:
                representative[p] = q
                break
    if all(representative[p] == p for p in range(n)):
        return automaton
    edges = [
        Edge(src=e.src, dst=representative[e.dst], guard=e.guard, marks=e.marks)
        for e in automaton.edges
        if representative[e.src] == e.src
    ]
    return Automaton(
        aps=automaton.aps,
        num_states=n,
        initial=representative[automaton.initial],
        edges=tuple(edges),
        num_acc=automaton.num_acc,
        state_names=automaton.state_names,
        formula=automaton.formula,
        state_based=automaton.state_based,
    )


def prune(
    automaton: Automaton, alphabet: Alphabet, sim: list[list[bool]], deadline: float
) -> Automaton:
    """Drop the cubes whose every letter has a strictly better alternative edge."""
    out: dict[int, list[Edge]] = defaultdict(list)
    for e in automaton.edges:
        out[e.src].append(e)
    kept: list[Edge] = []
    for src, edges in out.items():
        facts = [(alphabet.mask(e.guard), _bits(e.marks), e.dst) for e in edges]
        for e, (letters, marks, target) in zip(edges, facts, strict=True):
            work.charge(deadline, len(facts))
            better = 0
            for other_letters, other_marks, other_target in facts:
                if marks & ~other_marks or not sim[target][other_target]:
                    continue
                # Strictly better: not also dominated the other way round.
                if other_marks & ~marks == 0 and sim[other_target][target]:
                    continue
                better |= other_letters
            if better == 0:
                kept.append(e)
                continue
            left = letters & ~better
            if left == letters:
                kept.append(e)
                continue
            if not left:
                continue
            # Only the letters without a better alternative stay on the edge.
            guard = alphabet.guard(left)
            if guard is None:  # whole cubes only
                cubes = e.guard.args if isinstance(e.guard, Or) else (e.guard,)
                remaining = [c for c in cubes if alphabet.mask(c) & ~better]
                if len(remaining) == len(cubes):
                    kept.append(e)
                    continue
                guard = disjoin(remaining)
            kept.append(Edge(src=src, dst=e.dst, guard=guard, marks=e.marks))
    return _with_edges(automaton, kept)


def merge_transient(
    automaton: Automaton, alphabet: Alphabet, component: Sequence[int], deadline: float
) -> Automaton:
    """Replace a state by a state of the same language that cannot reach it.

    ``q`` cannot reach ``p``, and each simulates the other with the relaxed marks of
    :func:`simulation` (so ``L(p) = L(q)``): then every edge into ``p`` can go to ``q``
    instead.  The redirected edges leave states that reach ``p``, which ``q`` does not reach,
    so a run takes at most one of them and then continues from ``q`` with the same words ``p``
    accepted.  Typical case: an initial state ``F G F a`` whose only edge enters the SCC of
    ``G F a``."""
    relation = simulation(automaton, alphabet, deadline, component)
    n = automaton.num_states
    succ: list[set[int]] = [set() for _ in range(n)]
    for e in automaton.edges:
        succ[e.src].add(e.dst)
    edges = list(automaton.edges)
    initial = automaton.initial
    # Replacing keeps the language of every other state, so the relation stays true of the
    # states still there; reachability is recomputed on the edges as they are now.
    removed: set[int] = set()
    for p in range(n):
        if component[p] < 0:
            continue
        for q in range(n):
            if q == p or q in removed or not (relation[p][q] and relation[q][p]):
                continue
            work.charge(deadline, n)  # the search of _reaches
            if _reaches(succ, q, p):
                continue
            work.charge(deadline, len(edges))
            edges = [
                e if e.dst != p else Edge(src=e.src, dst=q, guard=e.guard, marks=e.marks)
                for e in edges
                if e.src != p
            ]
            for s in succ:
                if p in s:
                    s.discard(p)
                    s.add(q)
            succ[p] = set()
            removed.add(p)
            if initial == p:
                initial = q
            break
    if len(edges) == len(automaton.edges) and initial == automaton.initial:
        return automaton
    return dataclasses.replace(automaton, edges=tuple(edges), initial=initial)


def _reaches(succ: Sequence[set[int]], source: int, target: int) -> bool:
    seen = {source}
    stack = [source]
    while stack:
        state = stack.pop()
        if state == target:
            return True
        for nxt in succ[state]:
            if nxt not in seen:
                seen.add(nxt)
                stack.append(nxt)
    return False
