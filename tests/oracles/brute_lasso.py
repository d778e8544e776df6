"""Brute-force oracle for the witness's cost: explicit product, one Dijkstra per candidate.

Re-states the model of docs/planning.md ("Optimality") from the raw mesh arrays, without
tlmpc's product or search: product nodes are (triangle, entry edge, automaton state); a move
leaves through any edge but the entry edge (no bounce); a stutter stays.  The minimum is taken
over *every* accepting product edge ``u -> v`` reachable from the start, as
``d(start, u) + beta * (w(u, v) + d(v, u))``, and over every accepting stay ``d(start, u)``,
with no pruning and no cap.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence

import numpy as np
from starts import start_triangles

from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.guards import holds
from tlmpc.automata.model import Automaton

START = 3
STUTTER = 1e-9

Node = tuple[int, int, int]


def _mid(abstraction: Abstraction, t: int, i: int) -> np.ndarray:
    corners = abstraction.vertices[abstraction.triangles[t]]
    mid: np.ndarray = (corners[(i + 1) % 3] + corners[(i + 2) % 3]) / 2.0
    return mid


def move_cost(
    abstraction: Abstraction,
    t: int,
    entry: int,
    exit_edge: int,
    start_point: Sequence[float],
    metric: str,
) -> float:
    """Cost of leaving ``t`` through ``exit_edge`` having entered through ``entry``."""
    if metric == "hops":
        return 1.0
    origin = np.asarray(start_point) if entry == START else _mid(abstraction, t, entry)
    return float(np.linalg.norm(_mid(abstraction, t, exit_edge) - origin)) + STUTTER


def _successors(
    abstraction: Abstraction,
    automaton: Automaton,
    node: Node,
    start_point: Sequence[float],
    metric: str,
    blocked: dict[int, set[int]],
) -> list[tuple[Node, float, bool]]:
    t, entry, q = node
    full = frozenset(range(automaton.num_acc))
    found: list[tuple[Node, float, bool]] = []
    targets: list[tuple[int, int, float]] = [(t, entry, STUTTER)]
    for i in range(3):
        n = int(abstraction.neighbors[t, i])
        if n < 0 or i == entry or (entry == START and i in blocked.get(t, set())):
            continue
        slot = [int(x) for x in abstraction.neighbors[n]].index(t)
        targets.append((n, slot, move_cost(abstraction, t, entry, i, start_point, metric)))
    for tri, slot, weight in targets:
        letter = set(abstraction.labels(tri))
        for edge in automaton.edges:
            if edge.src == q and holds(edge.guard, letter):
                found.append(((tri, slot, edge.dst), weight, full <= edge.marks))
    return found


def _dijkstra(
    succ: dict[Node, list[tuple[Node, float, bool]]], sources: dict[Node, float]
) -> dict[Node, float]:
    dist: dict[Node, float] = {}
    heap = [(d, n) for n, d in sources.items()]
    heapq.heapify(heap)
    while heap:
        d, node = heapq.heappop(heap)
        if node in dist:
            continue
        dist[node] = d
        for nxt, w, _ in succ[node]:
            if nxt not in dist:
                heapq.heappush(heap, (d + w, nxt))
    return dist


def minimum_lasso_cost(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    start_point: Sequence[float],
    metric: str,
    beta: float,
) -> float:
    """The promised minimum (``inf`` when no lasso exists); ``automaton`` has <= 1 set."""
    # Every triangle holding the start point may come first; its edges through the point
    # are not left at the first move.
    blocked = start_triangles(abstraction, start_point)
    roots = {
        (start, START, e.dst): 0.0
        for start in blocked
        for e in automaton.edges
        if e.src == automaton.initial and holds(e.guard, set(abstraction.labels(start)))
    }
    succ: dict[Node, list[tuple[Node, float, bool]]] = {}
    stack = list(roots)
    while stack:
        node = stack.pop()
        if node in succ:
            continue
        succ[node] = _successors(abstraction, automaton, node, start_point, metric, blocked)
        stack.extend(n for n, _, _ in succ[node] if n not in succ)
    d0 = _dijkstra(succ, roots)
    best = math.inf
    for u, outs in succ.items():
        for v, w, accepting in outs:
            if not accepting:
                continue
            if v == u:  # an accepting stay
                best = min(best, d0[u])
                continue
            back = _dijkstra(succ, {v: 0.0}).get(u, math.inf)
            best = min(best, d0[u] + beta * (w + back))
    return best


def lasso_cost(
    abstraction: Abstraction,
    prefix: Sequence[int],
    cycle: Sequence[int],
    *,
    start_point: Sequence[float],
    metric: str,
    beta: float,
) -> float:
    """The cost of a witness's triangle sequence, recomputed from the mesh alone."""

    def edge(a: int, b: int) -> int:
        return [int(x) for x in abstraction.neighbors[a]].index(b)

    run = [*prefix, *cycle]
    entry = START
    total = 0.0
    costs = []
    for a, b in zip(run, [*run[1:], cycle[0]], strict=True):
        if a == b:  # a stay
            costs.append(0.0)
            continue
        costs.append(move_cost(abstraction, a, entry, edge(a, b), start_point, metric))
        entry = edge(b, a)
    # The last cost closes the cycle: it is only a move for a moving cycle.
    prefix_part = sum(costs[: len(prefix)])
    cycle_part = sum(costs[len(prefix) :]) if len(cycle) > 1 else 0.0
    total = prefix_part + beta * cycle_part
    return total
