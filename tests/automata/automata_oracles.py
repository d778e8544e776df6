"""Test oracles independent of the translator: LTL on lasso words, and automaton acceptance.

``tests/automata`` is not a package; test modules import this file by path via ``conftest``-free
``importlib`` (see ``load_helpers`` in each test).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedGlobally,
    BoundedUntil,
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

Letter = frozenset[str]


def evaluate(formula: Formula, prefix: Sequence[Letter], loop: Sequence[Letter]) -> bool:
    """Truth of ``formula`` at position 0 of ``prefix · loop^ω`` (loop non-empty).

    Each subformula becomes a truth vector over the ``len(prefix) + len(loop)`` positions; the
    temporal operators are least (U, F, M) or greatest (R, G, W) fixpoints of their one-step
    unfolding, iterated to stability on the lasso.
    """
    word = list(prefix) + list(loop)
    n = len(word)
    succ = [i + 1 if i + 1 < n else len(prefix) for i in range(n)]

    def fix(step: Callable[[int, list[bool]], bool], start: bool) -> list[bool]:
        value = [start] * n
        while True:
            new = [step(i, value) for i in range(n)]
            if new == value:
                return value
            value = new

    def ev(f: Formula) -> list[bool]:
        if isinstance(f, Const):
            return [f.value] * n
        if isinstance(f, Prop):
            return [f.name in letter for letter in word]
        if isinstance(f, Not):
            return [not x for x in ev(f.arg)]
        if isinstance(f, And):
            parts = [ev(a) for a in f.args]
            return [all(p[i] for p in parts) for i in range(n)]
        if isinstance(f, Or):
            parts = [ev(a) for a in f.args]
            return [any(p[i] for p in parts) for i in range(n)]
        if isinstance(f, Eventually):
            b = ev(f.arg)
            return fix(lambda i, v: b[i] or v[succ[i]], False)
        if isinstance(f, Globally):
            a = ev(f.arg)
            return fix(lambda i, v: a[i] and v[succ[i]], True)
        if isinstance(f, BoundedEventually | BoundedGlobally | BoundedUntil):
            raise ValueError(f"a word without times has no time bounds: {f}")
        left, right = ev(f.left), ev(f.right)
        if isinstance(f, Implies):
            return [not x or y for x, y in zip(left, right, strict=True)]
        if isinstance(f, Equiv):
            return [x == y for x, y in zip(left, right, strict=True)]
        if isinstance(f, Until):
            return fix(lambda i, v: right[i] or (left[i] and v[succ[i]]), False)
        if isinstance(f, WeakUntil):
            return fix(lambda i, v: right[i] or (left[i] and v[succ[i]]), True)
        if isinstance(f, Release):
            return fix(lambda i, v: right[i] and (left[i] or v[succ[i]]), True)
        if isinstance(f, StrongRelease):
            return fix(lambda i, v: right[i] and (left[i] or v[succ[i]]), False)
        raise TypeError(f"unknown node {f!r}")

    return ev(formula)[0]


Graph = dict[tuple[int, int], list[tuple[tuple[int, int], int]]]


def accepting_cycle(
    start: tuple[int, int],
    graph_of: Callable[[tuple[int, int]], list[tuple[tuple[int, int], int]]],
    full: int,
) -> bool:
    """Is there a reachable cycle whose edges' mark masks OR to ``full``? (Tarjan SCCs.)"""
    graph: Graph = {}
    stack = [start]
    while stack:
        node = stack.pop()
        if node in graph:
            continue
        graph[node] = graph_of(node)
        stack.extend(dst for dst, _ in graph[node] if dst not in graph)
    index: dict[tuple[int, int], int] = {}
    low: dict[tuple[int, int], int] = {}
    on: set[tuple[int, int]] = set()
    tstack: list[tuple[int, int]] = []
    comp: dict[tuple[int, int], int] = {}
    counter = [0]

    def strong(v: tuple[int, int]) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        tstack.append(v)
        on.add(v)
        for w, _ in graph[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            while True:
                w = tstack.pop()
                on.discard(w)
                comp[w] = index[v]
                if w == v:
                    break

    for v in list(graph):
        if v not in index:
            strong(v)
    union: dict[int, int] = {}
    cyclic: set[int] = set()
    for v, out in graph.items():
        for w, mask in out:
            if comp[v] == comp[w]:
                cyclic.add(comp[v])
                union[comp[v]] = union.get(comp[v], 0) | mask
    return any((union.get(c, 0) & full) == full for c in cyclic)


def accepts(automaton: object, prefix: Sequence[Letter], loop: Sequence[Letter]) -> bool:
    """Does the (generalized) Büchi automaton accept ``prefix · loop^ω``?"""
    from tlmpc.automata import guard_holds
    from tlmpc.automata.model import Automaton

    assert isinstance(automaton, Automaton)
    word = list(prefix) + list(loop)
    n = len(word)
    succ = [i + 1 if i + 1 < n else len(prefix) for i in range(n)]
    out: dict[int, list[tuple[int, int, object]]] = {}
    for e in automaton.edges:
        mask = 0
        for m in e.marks:
            mask |= 1 << m
        out.setdefault(e.src, []).append((e.dst, mask, e.guard))

    def graph_of(node: tuple[int, int]) -> list[tuple[tuple[int, int], int]]:
        pos, q = node
        return [
            ((succ[pos], dst), mask)
            for dst, mask, guard in out.get(q, [])
            if guard_holds(guard, word[pos])  # type: ignore[arg-type]
        ]

    full = (1 << automaton.num_acc) - 1
    return accepting_cycle((0, automaton.initial), graph_of, full)
