"""WDBA minimization for obligation formulas (Dax–Eisinger–Klaedtke, ATVA'07; Spot's
``minimize_obligation``).

An obligation property (a Boolean combination of safety and guarantee properties) is recognized
by a weak deterministic Büchi automaton, and the subset construction of any Büchi automaton for it
gives one: every cycle of an SCC of the subset automaton agrees on acceptance, so one lasso per
SCC, checked against the TGBA, decides the SCC.  The deterministic automaton is then minimized like
a DFA whose final states are those of accepting SCCs (for deterministic Büchi automata, states
with the same finite-word language to the final states accept the same infinite words).

The caller must only pass automata of obligation formulas (:func:`is_obligation` on the
formula); for other languages the subset construction is not sound.  Every step charges its work
(:mod:`tlmpc.automata.work`) and gives up (None) rather than overrun the budget.
"""

from __future__ import annotations

import functools
from collections import deque
from collections.abc import Sequence
from typing import assert_never

from tlmpc.automata import work
from tlmpc.automata.model import Automaton, Edge
from tlmpc.automata.nnf import Always, Binary, Bottom, Conj, Disj, Finally, Neg, Node, Pos, Top
from tlmpc.automata.simulation import Alphabet
from tlmpc.base.graphs import csr, strong_components
from tlmpc.ltl.ast import FALSE, Formula, Not, Prop, conjoin, disjoin

#: Subset construction is abandoned past this many subsets (the input is kept).
MAX_SUBSETS = 400
#: Over the full alphabet, at most this many propositions (2^n letters are enumerated).
MAX_APS = 8


def is_safety(f: Node) -> bool:
    """Syntactic safety (NNF): literals, & |, and G R W over safety formulas."""
    match f:
        case Top() | Bottom() | Pos() | Neg():
            return True
        case Conj(args=args) | Disj(args=args):
            return all(is_safety(a) for a in args)
        case Always(arg=arg):
            return is_safety(arg)
        case Binary(kind=kind, left=left, right=right):
            return kind in ("R", "W") and is_safety(left) and is_safety(right)
        case Finally():
            return False
        case _:
            assert_never(f)


def is_guarantee(f: Node) -> bool:
    """Syntactic guarantee (NNF): literals, & |, and F U M over guarantee formulas."""
    match f:
        case Top() | Bottom() | Pos() | Neg():
            return True
        case Conj(args=args) | Disj(args=args):
            return all(is_guarantee(a) for a in args)
        case Finally(arg=arg):
            return is_guarantee(arg)
        case Binary(kind=kind, left=left, right=right):
            return kind in ("U", "M") and is_guarantee(left) and is_guarantee(right)
        case Always():
            return False
        case _:
            assert_never(f)


def is_obligation(f: Node) -> bool:
    """Syntactic obligation: a Boolean combination of safety and guarantee formulas."""
    if is_safety(f) or is_guarantee(f):
        return True
    if isinstance(f, Conj | Disj):
        return all(is_obligation(a) for a in f.args)
    return False


def minimize_obligation(
    automaton: Automaton,
    letters: Sequence[frozenset[str]] | None,
    deadline: float,
) -> Automaton | None:
    """The minimized weak deterministic automaton, or None when out of budget or too big."""
    if automaton.num_acc == 0 and not automaton.edges:
        return None
    if letters is None and len(automaton.aps) > MAX_APS:
        return None
    try:
        return _minimize(automaton, letters, deadline)
    except work.OutOfBudget:
        return None


def _minimize(
    automaton: Automaton, letters: Sequence[frozenset[str]] | None, deadline: float
) -> Automaton | None:
    alphabet = Alphabet(automaton.aps, letters)
    size = alphabet.full.bit_length()
    everything = (1 << automaton.num_acc) - 1
    # succ[q][letter] = ((dst, marks), ...)
    succ: list[list[list[tuple[int, int]]]] = [
        [[] for _ in range(size)] for _ in range(automaton.num_states)
    ]
    for edge in automaton.edges:
        mask = alphabet.mask(edge.guard)
        marks = 0
        for m in edge.marks:
            marks |= 1 << m
        letter = 0
        while mask:
            if mask & 1:
                succ[edge.src][letter].append((edge.dst, marks))
            mask >>= 1
            letter += 1
    work.charge(deadline, len(automaton.edges) * size)
    start = frozenset([automaton.initial])
    index = {start: 0}
    subsets = [start]
    delta: list[list[int]] = []
    for subset in subsets:
        work.charge(deadline, size * len(subset))
        row = []
        for letter in range(size):
            target = frozenset(d for q in subset for d, _m in succ[q][letter])
            if not target:
                row.append(-1)
                continue
            if target not in index:
                if len(index) >= MAX_SUBSETS:
                    return None
                index[target] = len(subsets)
                subsets.append(target)
            row.append(index[target])
        delta.append(row)
    n = len(subsets)
    component = _sccs(delta)
    accepting_scc: dict[int, bool] = {}
    parent = _bfs_tree(delta)
    for state in range(n):
        c = component[state]
        if c in accepting_scc:
            continue
        cycle = _cycle(delta, component, state)
        if cycle is None:
            continue  # trivial SCC
        prefix = _path(parent, state)
        # the lasso's product with the automaton
        work.charge(deadline, (len(prefix) + len(cycle)) * automaton.num_states)
        accepting_scc[c] = _accepts(succ, automaton.initial, prefix, cycle, everything)
    final = [accepting_scc.get(component[s], False) for s in range(n)]
    block = _moore(delta, final)
    blocks = max(block) + 1
    grouped: dict[tuple[int, int, bool], int] = {}
    for state in range(n):
        b = block[state]
        for letter, successor in enumerate(delta[state]):
            if successor < 0:
                continue
            key = (b, block[successor], final[state])
            grouped[key] = grouped.get(key, 0) | 1 << letter
    edges = tuple(
        Edge(
            src=src,
            dst=dst,
            guard=_guard(mask, automaton.aps, letters, alphabet),
            marks=frozenset({0}) if accepting else frozenset(),
        )
        for (src, dst, accepting), mask in sorted(grouped.items())
    )
    return Automaton(
        aps=automaton.aps,
        num_states=blocks,
        initial=block[0],
        edges=edges,
        num_acc=1,
        state_names=tuple(f"[{b}]" for b in range(blocks)),
        formula=automaton.formula,
        state_based=False,
    )


def _sccs(delta: list[list[int]]) -> list[int]:
    """SCC number of every state (a negative entry of ``delta`` is a missing transition)."""
    return strong_components(*csr([[t for t in row if t >= 0] for row in delta]))


def _bfs_tree(delta: list[list[int]]) -> list[tuple[int, int]]:
    """``parent[s] = (previous state, letter)`` on shortest paths from state 0."""
    parent = [(-1, -1)] * len(delta)
    seen = {0}
    queue = deque([0])
    while queue:
        state = queue.popleft()
        for letter, target in enumerate(delta[state]):
            if target >= 0 and target not in seen:
                seen.add(target)
                parent[target] = (state, letter)
                queue.append(target)
    return parent


def _path(parent: list[tuple[int, int]], state: int) -> list[int]:
    letters = []
    while state != 0:
        previous, letter = parent[state]
        letters.append(letter)
        state = previous
    return letters[::-1]


def _cycle(delta: list[list[int]], component: list[int], state: int) -> list[int] | None:
    """Letters of a cycle from ``state`` back to it inside its SCC (None: trivial SCC)."""
    c = component[state]
    back: dict[int, tuple[int, int]] = {}
    queue: deque[int] = deque()
    for letter, target in enumerate(delta[state]):
        if target >= 0 and component[target] == c and target not in back:
            back[target] = (state, letter)
            queue.append(target)
    while queue:
        node = queue.popleft()
        if node == state:
            break
        for letter, target in enumerate(delta[node]):
            if target >= 0 and component[target] == c and target not in back:
                back[target] = (node, letter)
                queue.append(target)
    if state not in back:
        return None
    letters = []
    node = state
    while True:
        previous, letter = back[node]
        letters.append(letter)
        node = previous
        if node == state:
            break
    return letters[::-1]


def _accepts(
    succ: list[list[list[tuple[int, int]]]],
    initial: int,
    prefix: list[int],
    cycle: list[int],
    everything: int,
) -> bool:
    """Does the TGBA accept ``prefix cycle^ω``?  (Product with the lasso, then an SCC that
    lies in the loop part and carries every mark.)"""
    word = prefix + cycle
    loop = len(prefix)

    def after(position: int) -> int:
        return position + 1 if position + 1 < len(word) else loop

    nodes: dict[tuple[int, int], int] = {(initial, 0): 0}
    order = [(initial, 0)]
    adjacency: list[list[tuple[int, int]]] = []
    for q, position in order:
        row = []
        for dst, marks in succ[q][word[position]]:
            key = (dst, after(position))
            if key not in nodes:
                nodes[key] = len(order)
                order.append(key)
            row.append((nodes[key], marks))
        adjacency.append(row)
    delta = [[target for target, _m in row] for row in adjacency]
    component = _sccs(delta)
    collected: dict[int, int] = {}
    for source, row in enumerate(adjacency):
        for target, marks in row:
            if component[source] == component[target]:
                collected[component[source]] = collected.get(component[source], 0) | marks
    return any(marks & everything == everything for marks in collected.values())


def _moore(delta: list[list[int]], final: list[bool]) -> list[int]:
    """Coarsest partition respecting ``final`` and the letter-wise successors' blocks."""
    block = [1 if f else 0 for f in final]
    while True:
        signatures: dict[tuple[int, tuple[int, ...]], int] = {}
        new_block = []
        for state, row in enumerate(delta):
            key = (block[state], tuple(block[t] if t >= 0 else -1 for t in row))
            new_block.append(signatures.setdefault(key, len(signatures)))
        if len(signatures) == len(set(block)):
            # Renumber so that the initial state's block comes first.
            return _renumber_blocks(new_block)
        block = new_block


def _renumber_blocks(block: list[int]) -> list[int]:
    mapping: dict[int, int] = {}
    return [mapping.setdefault(b, len(mapping)) for b in block]


def _guard(
    mask: int,
    aps: tuple[str, ...],
    letters: Sequence[frozenset[str]] | None,
    alphabet: Alphabet,
) -> Formula:
    """A propositional formula enabled exactly on the letters of ``mask``."""
    if mask == alphabet.full:
        return conjoin([])
    if letters is not None:
        cubes = []
        for i, letter in enumerate(letters):
            if mask >> i & 1:
                cubes.append(conjoin([Prop(a) if a in letter else Not(Prop(a)) for a in aps]))
        return disjoin(cubes) if cubes else FALSE
    return disjoin(_cover(mask, len(aps), aps)) if mask else FALSE


def _cover(mask: int, n: int, aps: tuple[str, ...]) -> list[Formula]:
    """Cubes covering exactly the valuations of ``mask`` (greedy prime expansion)."""
    remaining = mask
    cubes = []
    while remaining:
        valuation = (remaining & -remaining).bit_length() - 1
        # Start from the minterm and drop literals while the cube stays inside ``mask``.
        fixed = {i: bool(valuation >> i & 1) for i in range(n)}
        for i in range(n):
            trial = dict(fixed)
            del trial[i]
            if _cube_mask(trial, n) & ~mask == 0:
                fixed = trial
        remaining &= ~_cube_mask(fixed, n)
        cubes.append(
            conjoin([Prop(aps[i]) if value else Not(Prop(aps[i])) for i, value in fixed.items()])
        )
    return cubes


def _cube_mask(fixed: dict[int, bool], n: int) -> int:
    """The valuations (bit ``v`` = valuation ``v``) where each fixed proposition has its value:
    an intersection of one precomputed mask per literal, not a scan of the 2^n valuations."""
    literal = _literal_masks(n)
    mask = (1 << (1 << n)) - 1
    for i, value in fixed.items():
        mask &= literal[i] if value else ~literal[i]
    return mask


@functools.cache
def _literal_masks(n: int) -> tuple[int, ...]:
    """Per proposition ``i``, the valuations over ``n`` propositions where ``i`` is true."""
    masks = []
    for i in range(n):
        mask = 0
        for valuation in range(1 << n):
            if valuation >> i & 1:
                mask |= 1 << valuation
        masks.append(mask)
    return tuple(masks)
