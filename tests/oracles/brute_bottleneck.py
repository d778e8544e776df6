"""Brute-force oracle for the largest disturbance any plan on a mesh rejects.

Re-states docs/control.md ("The largest disturbance a mesh supports") from the raw mesh arrays,
without tlmpc's product, widths or search: the product is built explicitly (as
tests/oracles/brute_lasso.py builds it: nodes (triangle, entry edge, automaton state), no
bounce); a step's width is the smallest push of its corners, from the corner angles by arccos
(sin(a / 2) where both facets are kept, cos(a / 2) on the exit edge; a stay keeps all three).
Then *every* width that occurs is tried as a floor, one after the other (no bisection, no
strongly connected components): a lasso of steps no narrower exists when an accepting edge
is reached from the start and its head reaches its tail again by plain depth-first searches
(a return that never leaves the cell is a stay, which needs the triangle's stay width), or an
accepting stay is reached. The largest floor with a lasso is the value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from brute_lasso import START, _successors
from starts import start_triangles

from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.guards import holds
from tlmpc.automata.model import Automaton

Node = tuple[int, int, int]
#: node -> successor -> (width, carries the mark)
Edges = dict[Node, dict[Node, tuple[float, bool]]]


def corner_angles(abstraction: Abstraction, t: int) -> list[float]:
    """The interior angles of triangle ``t`` at its three corners (radians, by arccos)."""
    corners = abstraction.vertices[abstraction.triangles[t]]
    angles = []
    for k in range(3):
        u = corners[(k + 1) % 3] - corners[k]
        v = corners[(k + 2) % 3] - corners[k]
        cosine = float(u @ v) / (float(np.linalg.norm(u)) * float(np.linalg.norm(v)))
        angles.append(math.acos(max(-1.0, min(1.0, cosine))))
    return angles


def move_width(abstraction: Abstraction, t: int, exit_edge: int) -> float:
    """What leaving ``t`` through edge ``exit_edge`` rejects, over max_speed."""
    angles = corner_angles(abstraction, t)
    return min(
        math.sin(angles[k] / 2) if k == exit_edge else math.cos(angles[k] / 2) for k in range(3)
    )


def stay_width(abstraction: Abstraction, t: int) -> float:
    """What staying in ``t`` rejects, over max_speed."""
    return min(math.sin(a / 2) for a in corner_angles(abstraction, t))


def product_graph(
    abstraction: Abstraction, automaton: Automaton, start_point: Sequence[float]
) -> tuple[Edges, list[Node]]:
    """The reachable product, each edge with its width (``inf`` for a stutter) and whether
    it carries the acceptance mark; and the initial nodes."""
    blocked = start_triangles(abstraction, start_point)
    roots = sorted(
        {
            (start, START, e.dst)
            for start in blocked
            for e in automaton.edges
            if e.src == automaton.initial and holds(e.guard, set(abstraction.labels(start)))
        }
    )
    graph: Edges = {}
    stack = list(roots)
    while stack:
        node = stack.pop()
        if node in graph:
            continue
        out = graph[node] = {}
        t = node[0]
        for following, _, accepting in _successors(
            abstraction, automaton, node, start_point, "hops", blocked
        ):
            n = following[0]
            if n == t:
                width = math.inf
            else:
                sides = [int(x) for x in abstraction.neighbors[t]]
                width = move_width(abstraction, t, sides.index(n))
            marked = out[following][1] if following in out else False
            out[following] = (width, marked or accepting)
            stack.append(following)
    return graph, roots


def reach(graph: Edges, sources: list[Node], floor: float, *, reverse: bool) -> set[Node]:
    """The nodes reached from (or, with ``reverse``, reaching) ``sources`` along edges of
    width >= ``floor`` (a plain depth-first search)."""
    if reverse:
        flipped: Edges = {}
        for node, out in graph.items():
            for other, data in out.items():
                flipped.setdefault(other, {})[node] = data
        graph = flipped
    seen = set(sources)
    stack = list(sources)
    while stack:
        node = stack.pop()
        for other, (width, _) in graph.get(node, {}).items():
            if width >= floor and other not in seen:
                seen.add(other)
                stack.append(other)
    return seen


def has_lasso(abstraction: Abstraction, graph: Edges, roots: list[Node], floor: float) -> bool:
    """By definition: an accepting edge u -> v with u reached from the start and v reaching
    u again, every step of width >= ``floor`` (a return that never leaves the cell is a stay,
    counted by the triangle's stay width), or an accepting stay."""
    reached = reach(graph, roots, floor, reverse=False)
    edges = [(u, v, data) for u, out in graph.items() for v, data in out.items()]
    for u, v, (width, accepting) in edges:
        if not accepting or u not in reached or width < floor:
            continue
        cell = u[:2]
        if u == v:  # an accepting stutter loop: the run ends staying
            if stay_width(abstraction, u[0]) >= floor:
                return True
            continue
        back = reach(graph, [v], floor, reverse=False)
        if u not in back:
            continue
        into_u = reach(graph, [u], floor, reverse=True)
        if any(node[:2] != cell for node in back & into_u):
            return True  # a cycle through u -> v that leaves the cell: it moves
        if v[:2] == cell and stay_width(abstraction, u[0]) >= floor:
            return True  # a cycle of stutter edges inside one cell: a stay
    return False


def widest_lasso(
    abstraction: Abstraction, automaton: Automaton, start_point: Sequence[float]
) -> float | None:
    """The largest w such that some accepting lasso uses only steps of width >= w, tried at
    every width that occurs on the mesh, one after the other (None: no lasso at all)."""
    graph, roots = product_graph(abstraction, automaton, start_point)
    candidates = {width for out in graph.values() for width, _ in out.values()}
    candidates |= {stay_width(abstraction, t) for t in range(abstraction.num_triangles)}
    best: float | None = None
    for floor in sorted(w for w in candidates if math.isfinite(w)):
        if has_lasso(abstraction, graph, roots, floor):
            best = floor
    return best
