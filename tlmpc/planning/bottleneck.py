"""The largest disturbance any plan on a mesh rejects: a widest-lasso search over the product.

A plan's steps reject every disturbance below the smallest *width* of its steps (a move's or a
final stay's smallest corner push, :func:`tlmpc.planning.robust.step_widths`) and none from
there on. Over every accepting lasso of the product (no U-turns, no vertex passages: neither
is realised under a disturbance) the best such bound is

    W* = max over lassos of min(widths of the prefix's and the cycle's steps),

a bottleneck (maximin) value. The steps are the moves (a stutter inside a triangle is no
step of its own: its controller is the move that follows) and, for a lasso that ends
staying, the stay; a cycle of stutter edges alone (the automaton moving while the robot
stays, after degeneralization) is a stay too.

W* is one of the finitely many widths, and "some lasso uses only steps of width >= w" is
monotone in w, so a binary search over the sorted distinct widths finds it exactly: each
probe keeps the product's edges of width >= w and asks whether an accepting stay is
reachable from an initial node, or an accepting edge lies on a cycle of the kept graph
(its strongly connected component). A component inside one cell (one triangle and entry
slot) holds stutter edges alone: its cycles are stays and count only where the triangle's
stay is wide enough. The planner, restricted to the steps wider than d / max_speed plus the
controllers' tolerance, finds a plan exactly when W* exceeds that.
"""

from __future__ import annotations

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.degeneralize import degeneralize
from tlmpc.automata.model import Automaton
from tlmpc.base.graphs import strong_components
from tlmpc.ltl.ast import Formula
from tlmpc.mission.model import Options
from tlmpc.planning.boundary import start_cells, start_point_label
from tlmpc.planning.budget import estimate_product
from tlmpc.planning.explain import invariant_mask
from tlmpc.planning.product import SLOTS, Product, build_product
from tlmpc.planning.robust import step_widths


def supported_ratio(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    formula: Formula,
    options: Options,
    start_point: tuple[float, float],
    cells: bool = False,
) -> float | None:
    """W* / max_speed for the task ``automaton`` on ``abstraction`` (see the module doc):
    the largest disturbance ratio some plan on this mesh rejects (every ratio below it, plus
    the controllers' tolerance, has a plan). None when the product has no lasso without
    U-turns or vertex passages, or is too large to build (the guided search's size).

    With ``cells``, the steps are the convex cells' (:mod:`tlmpc.planning.cells`): a move
    inside one cell is no step of its own, a cycle inside one cell is that cell's stay, and
    the product's nodes carry the cell the robot entered its cell from
    (:mod:`tlmpc.planning.cell_product`), so no lasso leaves a cell back across the
    interface it came in by (no cell field does): the value is what plans on cells reject."""
    if not estimate_product(abstraction, automaton).fits:
        return None
    working = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    closed = options.boundary == "closed"
    product = build_product(
        abstraction,
        working,
        allowed=invariant_mask(abstraction, formula),
        start_point=start_point,
        metric="hops",  # weights play no part in a bottleneck
        starts=start_cells(abstraction, start_point),
        convention=options.boundary,
        start_label=start_point_label(abstraction, start_point) if closed else (),
    )
    if not cells:
        moves, stays = step_widths(abstraction)
        return widest_lasso(product, abstraction, moves, stays)
    from tlmpc.planning.cell_product import cell_product
    from tlmpc.planning.cells import cell_widths, partition

    partitioned = partition(abstraction)
    moves, stays = cell_widths(partitioned)
    on = cell_product(product, partitioned.cell_of)
    return widest_lasso(
        on.product, abstraction, moves, stays, groups=partitioned.cell_of, origin=on.origin
    )


def edge_widths(
    product: Product, abstraction: Abstraction, moves: FloatArray, origin: IntArray | None = None
) -> FloatArray:
    """Per product edge: the width of its move, ``inf`` for a stutter edge (no step);
    ``origin`` maps the nodes of a product on cells to the triangles' product's."""
    graph = product.graph
    nq = product.num_automaton_states
    tails, heads = graph.sources, graph.targets
    if origin is not None:
        tails, heads = origin[tails], origin[heads]
    here = tails // nq // SLOTS
    there = heads // nq // SLOTS
    widths = np.full(graph.nnz, np.inf)
    moving = np.flatnonzero(here != there)
    sides = abstraction.neighbors[here[moving]] == there[moving, None]
    exits = np.argmax(sides, axis=1)
    widths[moving] = moves[here[moving], exits]
    return widths


def widest_lasso(
    product: Product,
    abstraction: Abstraction,
    moves: FloatArray,
    stays: FloatArray,
    groups: IntArray | None = None,
    origin: IntArray | None = None,
) -> float | None:
    """The bottleneck value of the product's accepting lassos (None when there is none);
    ``groups`` (per triangle) joins triangles into cells whose inner moves are no steps,
    ``origin`` maps the nodes of a product on cells to the triangles' product's."""
    widths = edge_widths(product, abstraction, moves, origin)
    candidates = np.unique(np.concatenate([widths[np.isfinite(widths)], stays]))
    first = float(candidates[0]) if len(candidates) else 0.0
    if not len(candidates) or not _has_lasso(product, widths, stays, first, groups, origin):
        return None
    low, high = 0, len(candidates) - 1  # the lasso exists at candidates[low]
    while low < high:
        middle = (low + high + 1) // 2
        if _has_lasso(product, widths, stays, float(candidates[middle]), groups, origin):
            low = middle
        else:
            high = middle - 1
    return float(candidates[low])


def _has_lasso(
    product: Product,
    widths: FloatArray,
    stays: FloatArray,
    floor: float,
    groups: IntArray | None = None,
    origin: IntArray | None = None,
) -> bool:
    """Whether an accepting lasso uses only steps of width >= ``floor``."""
    graph = product.graph
    nq = product.num_automaton_states
    kept = widths >= floor
    indptr = np.zeros(graph.num_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(graph.sources[kept], minlength=graph.num_nodes), out=indptr[1:])
    targets = graph.targets[kept]  # the graph's edges are grouped by source: still CSR
    # Tarjan's search from the initial nodes labels exactly the nodes they reach.
    component = np.asarray(
        strong_components(indptr, targets, roots=product.initial.tolist()), dtype=np.int64
    )
    wide_stay = stays >= floor
    nodes = np.arange(graph.num_nodes) if origin is None else origin
    triangle_of = nodes // nq // SLOTS
    if (product.stutter_accepting & (component >= 0) & wide_stay[triangle_of]).any():
        return True
    accepting = np.flatnonzero(product.accepting & kept)
    heads, tails = graph.sources[accepting], graph.targets[accepting]
    inside = (component[heads] >= 0) & (component[heads] == component[tails])
    if not inside.any():
        return False
    # A component spanning two cells has a cycle through each of its edges that moves; one
    # inside a single cell is a stay of that triangle.
    cell = nodes // nq
    if groups is not None:
        cell = groups[triangle_of]
    members = component >= 0
    count = int(component.max()) + 1
    lowest = np.full(count, np.iinfo(np.int64).max)
    highest = np.full(count, -1)
    np.minimum.at(lowest, component[members], cell[members])
    np.maximum.at(highest, component[members], cell[members])
    looped = component[heads[inside]]
    moving = lowest[looped] != highest[looped]
    staying = wide_stay[triangle_of[heads[inside]]]
    return bool((moving | staying).any())
