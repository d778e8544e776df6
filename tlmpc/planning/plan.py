"""Stage 5: a minimum-cost accepting lasso of D × A, or an explanation of why none exists.

Cost of a lasso = prefix + beta * cycle.  Automata with two or more acceptance sets are
degeneralized first, so every search below handles one set (see docs/planning.md for the
optimality statement).  Two kinds of cycles are considered:

* a *stay*: the robot converges inside one triangle whose stutter loop is accepting (cost 0);
* a *moving cycle* through an accepting product edge ``u -> v``: one shortest-path search
  from the initial nodes gives every prefix cost d0(u); candidates are taken in increasing
  order of the lower bound d0(u) + beta * w(u, v), each closed by a search from v back to u,
  and the search stops when the bound reaches the best lasso found.

The searches are :func:`tlmpc.planning.search.shortest_paths` (its tie-break among equal
paths is stated there).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.degeneralize import degeneralize
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import NoPlanError
from tlmpc.base.graphs import strong_components
from tlmpc.ltl.ast import Formula
from tlmpc.mission.model import Options
from tlmpc.planning.boundary import start_cells, start_point_label
from tlmpc.planning.budget import estimate_product, passages_too_large
from tlmpc.planning.explain import explain_no_plan, invariant_mask
from tlmpc.planning.guided import guided_lasso
from tlmpc.planning.lazy import lazy_product
from tlmpc.planning.model import Witness
from tlmpc.planning.passages import PassageCells, add_vertex_passages
from tlmpc.planning.product import SLOTS, START_SLOT, BoolArray, Product, build_product
from tlmpc.planning.robust import TOLERANCE, realisable
from tlmpc.planning.search import closing_searches, shortest_paths
from tlmpc.planning.timing import MoveTimes

#: At most this many cycle candidates are closed with a shortest-path search; past it the
#: witness is the best found and records ``optimal: false``.
MAX_CYCLE_SEARCHES = 40
#: Closing searches run together up to this many product nodes in all (their arrays).
BATCH_NODES = 4_000_000


def _path(predecessors: IntArray, target: int) -> list[int]:
    path = [target]
    while predecessors[path[-1]] >= 0:
        path.append(int(predecessors[path[-1]]))
    path.reverse()
    return path


def _collapse(
    nodes: list[int], nq: int, cells: PassageCells | None = None
) -> tuple[list[int], list[int], dict[int, int]]:
    """Triangles of a product path with stutter steps merged, the automaton state after
    reading each triangle (the last one of its stutter group), and the vertex passages
    (index of the triangle left through a vertex -> that vertex)."""
    triangles: list[int] = []
    states: list[int] = []
    through: dict[int, int] = {}
    previous = -1
    for node in nodes:
        tri = (node // nq) // SLOTS if cells is None else cells.triangle_of(node, nq)
        q = node % nq
        vertex = None if cells is None else cells.vertex_of(node, nq)
        # A passage back into the same triangle (a U-turn at a vertex, only while searching
        # with bounces) is a step of its own, not a stutter.
        entered = vertex is not None and node // nq != previous // nq
        previous = node
        if triangles and triangles[-1] == tri and not entered:
            states[-1] = q
        else:
            if vertex is not None and triangles:
                through[len(triangles) - 1] = vertex
            triangles.append(tri)
            states.append(q)
    return triangles, states, through


def _path_cost(product: Product, nodes: list[int]) -> float:
    # Added up left to right, one edge after the other (the sum the searches make).
    return float(sum(product.graph.path_weights(nodes)))


def plan(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    formula: Formula,
    options: Options,
    start_point: tuple[float, float] | None = None,
    bounces: bool = False,
    resume: frozenset[int] | None = None,
    passages: bool = False,
    guided: bool | None = None,
    reject: float | None = None,
    times: MoveTimes | None = None,
    on_cells: bool = False,
) -> Witness:
    """A minimum-cost accepting lasso (raises :class:`NoPlanError` with an explanation).

    With ``bounces=True`` the lasso may leave a triangle through its entry edge (a U-turn the
    controllers cannot realise on this mesh; :mod:`tlmpc.planning.complete` refines those).
    ``resume`` re-plans a run under way: the robot is in the start triangle and has already
    read its label, the (degeneralized) automaton being in any of these states.
    ``passages=True`` also lets the lasso pass through mesh vertices where labels meet
    (:mod:`tlmpc.planning.passages`).  ``guided`` searches the product expanded on demand
    (:mod:`tlmpc.planning.guided`: the same cost, for products too large to build); by
    default only when the product would not fit the budget (:mod:`tlmpc.planning.budget`).
    With ``reject`` (a disturbance over max_speed) only the moves and stays the controllers
    realise under it are used (:mod:`tlmpc.planning.robust`); with ``on_cells``, those the
    convex cells' fields realise (:mod:`tlmpc.planning.cells`), searched on a product that
    also rules out turning back across an interface and loops inside a cell whose stay is too
    narrow (:mod:`tlmpc.planning.cell_product`; the guided search leaves both to the check
    of the plan found).
    Under ``options.cost: time`` the moves weigh ``times`` (:mod:`tlmpc.planning.timing`;
    without it, their lengths at unit speed).
    """
    started = time.perf_counter()
    if options.cost == "time" and times is None:
        times = MoveTimes(speed=1.0)
    allowed = invariant_mask(abstraction, formula)
    working = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    if start_point is None:
        x, y = abstraction.corners(abstraction.start).mean(axis=0).tolist()
        start_point = (float(x), float(y))
    starts = start_cells(abstraction, start_point)
    # Only the closed convention reads the start point's own letter.
    closed = options.boundary == "closed"
    start_label = start_point_label(abstraction, start_point) if closed else ()

    def why() -> NoPlanError:
        return NoPlanError(
            explain_no_plan(
                abstraction,
                automaton,
                formula,
                allowed,
                starts=starts,
                start_label=start_label if closed else None,
            )
        )

    realisable_steps = None if reject is None else realisable(abstraction, reject)
    partitioned = None
    if reject is not None and on_cells:
        from tlmpc.planning.cells import cell_realisable, partition

        partitioned = partition(abstraction)
        realisable_steps = cell_realisable(partitioned, reject, TOLERANCE)
    if guided is None:
        guided = not estimate_product(abstraction, automaton).fits
    if guided:
        if passages:
            raise passages_too_large(abstraction, automaton)
        lazy = lazy_product(
            abstraction,
            working,
            allowed=allowed,
            start_point=start_point,
            metric=options.cost,
            starts=starts,
            convention=options.boundary,
            start_label=start_label,
            bounces=bounces,
            realisable=realisable_steps,
            times=times,
        )
        if resume is not None:
            initial = _resumed(abstraction, allowed, working, resume)
            lazy = dataclasses.replace(lazy, initial=initial)
        found = guided_lasso(
            lazy,
            np.repeat(allowed, SLOTS),
            beta=options.beta,
            max_searches=MAX_CYCLE_SEARCHES,
        )
        if found is None or not working.edges:
            raise why()
        return _witness(
            abstraction,
            working.num_states,
            lambda nodes: float(sum(lazy.path_weights(nodes))),
            (found.cost, found.prefix, found.cycle),
            options,
            started,
            found.searches,
            found.optimal,
            working,
            found.reached,
            {"product_nodes": lazy.num_nodes, "search": "guided", "search_rounds": found.rounds},
        )
    product = build_product(
        abstraction,
        working,
        allowed=allowed,
        start_point=start_point,
        metric=options.cost,
        starts=starts,
        convention=options.boundary,
        start_label=start_label,
        bounces=bounces,
        realisable=realisable_steps,
        times=times,
    )
    cells: PassageCells | None = None
    if passages:
        product, cells = add_vertex_passages(
            product,
            abstraction,
            working,
            allowed=allowed,
            starts=starts,
            start_point=start_point,
            metric=options.cost,
            convention=options.boundary,
            bounces=bounces,
            times=times,
        )

    if resume is not None:
        product = dataclasses.replace(
            product, initial=_resumed(abstraction, allowed, working, resume)
        )
    triangles_product, origin = product, None
    if partitioned is not None and realisable_steps is not None and not passages:
        # On cells: no turning back across an interface, no loop inside a cell whose stay
        # is too narrow (tlmpc.planning.cell_product); the lasso found maps back by origin.
        from tlmpc.planning.cell_product import cell_product

        on = cell_product(product, partitioned.cell_of, realisable_steps[1])
        product, origin = on.product, on.origin
    if len(product.initial) == 0 or not working.edges:
        raise why()
    # A stay ends the search early: no lasso costs less than its prefix (see module doc).
    stays = product.stutter_accepting if product.stutter_accepting.any() else None
    dist, pred = shortest_paths(product.graph, product.initial, goals=stays)
    best: tuple[float, list[int], list[int]] | None = None  # cost, prefix nodes, cycle nodes
    # Stays: an accepting stutter loop.
    stay_nodes = np.flatnonzero(product.stutter_accepting & np.isfinite(dist))
    if len(stay_nodes):
        goal = int(stay_nodes[np.argmin(dist[stay_nodes])])
        best = (float(dist[goal]), _path(pred, goal), [goal])
    # Moving cycles through accepting edges.
    graph = product.graph
    marked = np.flatnonzero(product.accepting)
    marked = marked[np.isfinite(dist[graph.source_of(marked)])]
    # In (u, v) order: equal bounds are closed in that order (a stable sort below).
    marked = marked[np.lexsort((graph.targets[marked], graph.source_of(marked)))]
    best, searches, exhausted = _close_cycles(product, dist, pred, marked, best, options.beta)
    if best is None and not exhausted:
        # The cap stopped the search before any cycle closed.  Only edges inside one strongly
        # connected component close; keeping those, the first search succeeds, so the cap
        # never hides the existence of a lasso (computed only here: it costs a graph pass).
        scc = np.asarray(strong_components(graph.indptr, graph.targets))
        closable = scc[graph.source_of(marked)] == scc[graph.targets[marked]]
        best, more, exhausted = _close_cycles(
            product, dist, pred, marked[closable], None, options.beta
        )
        searches += more
    if best is None:
        raise why()
    reached = int(np.isfinite(dist).sum())
    if origin is not None:
        # the triangles' product's nodes: those reached, and the lasso's
        reached = len(np.unique(origin[np.isfinite(dist)]))
        cost, prefix_nodes, cycle_nodes = best
        best = (cost, origin[prefix_nodes].tolist(), origin[cycle_nodes].tolist())
    return _witness(
        abstraction,
        triangles_product.num_automaton_states,
        lambda nodes: _path_cost(triangles_product, nodes),
        best,
        options,
        started,
        searches,
        exhausted,
        working,
        reached,
        {
            "product_nodes": triangles_product.num_nodes,
            "product_edges": int(triangles_product.graph.nnz),
        },
        cells,
    )


def _resumed(
    abstraction: Abstraction, allowed: BoolArray, automaton: Automaton, resume: frozenset[int]
) -> IntArray:
    """The initial nodes of a re-plan under way: the start triangle's start slot, in any
    of the states ``resume``."""
    nodes = sorted(
        (abstraction.start * SLOTS + START_SLOT) * automaton.num_states + q for q in resume
    )
    return np.array(nodes if allowed[abstraction.start] else [], dtype=np.int64)


def _close_cycles(
    product: Product,
    dist: FloatArray,
    pred: IntArray,
    marked: IntArray,
    best: tuple[float, list[int], list[int]] | None,
    beta: float,
) -> tuple[tuple[float, list[int], list[int]] | None, int, bool]:
    """Close the accepting edges ``u -> v`` (indices ``marked`` of the product's edges) in
    order of their lower bound (see the module doc).

    Returns the best lasso (or the incumbent ``best``), the searches made, and whether the
    candidates were exhausted (False when :data:`MAX_CYCLE_SEARCHES` cut the search).
    """
    searches = 0
    if not len(marked):
        return best, searches, True
    graph = product.graph
    us = graph.source_of(marked)
    vs = graph.targets[marked]
    edge_w = graph.weights[marked]
    bound = dist[us] + beta * edge_w
    order = np.argsort(bound, kind="stable").tolist()
    # The closing searches run several at a time (they share the search's rounds), each with
    # the limit the incumbent allows when the batch starts; the candidates are then taken in
    # order exactly as one search at a time would take them (a distance beyond the limit the
    # incumbent allows by then counts as unreached, as that search would have left it).
    batch = max(1, min(MAX_CYCLE_SEARCHES, BATCH_NODES // max(graph.num_nodes, 1)))
    closed: dict[int, tuple[float, list[int]]] = {}
    for position, index in enumerate(order):
        if best is not None and bound[index] >= best[0]:
            break
        if searches >= MAX_CYCLE_SEARCHES:
            return best, searches, False
        if index not in closed:
            chosen: list[int] = []
            for ahead in order[position:]:
                if len(chosen) == min(batch, MAX_CYCLE_SEARCHES - searches):
                    break
                if best is not None and bound[ahead] >= best[0]:
                    break
                chosen.append(ahead)
            limits = np.array(
                [
                    np.inf if best is None else (best[0] - bound[k]) / max(beta, 1e-12)
                    for k in chosen
                ]
            )
            distances, paths = closing_searches(graph, vs[chosen], us[chosen], limits)
            closed = {k: (float(distances[j]), paths[j]) for j, k in enumerate(chosen)}
        searches += 1
        limit = np.inf if best is None else (best[0] - bound[index]) / max(beta, 1e-12)
        back, back_path = closed[index]  # back_path: v, ..., u
        if not (np.isfinite(back) and back <= limit):
            continue  # unreached, or farther than a search from here on would look
        u = int(us[index])
        total = float(dist[u] + beta * (edge_w[index] + back))
        if best is None or total < best[0] - 1e-12:
            best = (total, _path(pred, u), [u, *back_path[:-1]])
    return best, searches, True


def _witness(
    abstraction: Abstraction,
    nq: int,
    path_cost: Callable[[list[int]], float],
    best: tuple[float, list[int], list[int]],
    options: Options,
    started: float,
    searches: int,
    exhausted: bool,
    automaton: Automaton,
    reached: int,
    sizes: dict[str, Any],
    cells: PassageCells | None = None,
) -> Witness:
    _, prefix_nodes, cycle_nodes = best
    anchor = cycle_nodes[0]
    # prefix_nodes ends at the anchor; the cycle starts at the anchor's triangle.
    prefix_tris, prefix_states, prefix_through = _collapse(prefix_nodes, nq, cells)
    cycle_tris, cycle_states, cycle_through = _collapse(cycle_nodes, nq, cells)
    anchor_tri = (anchor // nq) // SLOTS if cells is None else cells.triangle_of(anchor, nq)
    # Drop the anchor's own triangle from the prefix: it opens the cycle.
    if prefix_tris and prefix_tris[-1] == anchor_tri:
        prefix_tris, prefix_states = prefix_tris[:-1], prefix_states[:-1]
    # A moving cycle whose last triangle equals its first (stutter at the anchor) is merged.
    if len(cycle_tris) > 1 and cycle_tris[-1] == cycle_tris[0]:
        cycle_tris, cycle_states = cycle_tris[:-1], cycle_states[:-1]
    # Vertex passages by index into prefix + cycle (the last cycle index: into cycle[0]).
    through = {i: v for i, v in prefix_through.items() if i < len(prefix_tris)}
    through.update({len(prefix_tris) + i: v for i, v in cycle_through.items()})
    wrap = None if cells is None or len(cycle_nodes) == 1 else cells.vertex_of(anchor, nq)
    if wrap is not None:
        through[len(prefix_tris) + len(cycle_tris) - 1] = wrap
    prefix_cost = path_cost(prefix_nodes)
    cycle_cost = 0.0 if len(cycle_nodes) == 1 else path_cost([*cycle_nodes, anchor])
    stats: dict[str, Any] = {
        **sizes,
        "product_reached": reached,
        "cycle_searches": searches,
        "optimal": exhausted,
        "automaton_states": automaton.num_states,
        "seconds": round(time.perf_counter() - started, 6),
    }
    return Witness(
        prefix=tuple(prefix_tris),
        cycle=tuple(cycle_tris),
        prefix_states=tuple(prefix_states),
        cycle_states=tuple(cycle_states),
        word=tuple(abstraction.labels(t) for t in (*prefix_tris, *cycle_tris)),
        cost=prefix_cost + options.beta * cycle_cost,
        metric=options.cost,
        beta=options.beta,
        prefix_cost=prefix_cost,
        cycle_cost=cycle_cost,
        stats=stats,
        passages=tuple(sorted(through.items())),
    )
