"""The product of a plan on convex cells: nodes that know how the robot entered its cell.

On cells (:mod:`tlmpc.planning.cells`) two conditions on a plan are not properties of a
triangle's move alone, and the triangles' product (:mod:`tlmpc.planning.product`) cannot see
them:

* **no turning back**: a cell field leaves its cell across any interface but the one the
  robot came in by (:func:`tlmpc.planning.cells.group_bounces`): the move from cell C to C'
  is realisable after entering C from any cell but C';
* **a loop inside one cell is a stay**: the cell's label is the same everywhere in it, so a
  cycle that never leaves the cell is that cell's stay (the radial law), and realisable only
  where the cell's stay is.

:func:`cell_product` builds from the triangles' product one that carries both:

* every node (t, s, q) is copied once per way into t's cell: from the start (the copy keeps
  the node's own number) and from each neighbouring cell some move of the product enters it
  from (numbered after the product's nodes, node by node). A move inside the cell keeps the
  way in; a move from C into C' leads to the copy of C' entered from C, and exists only in
  the copies of C not entered from C';
* with ``stays_ok``, in a cell whose stay is not realisable, an accepting edge inside the
  cell leads to a *pending* copy of its head, unmarked: a pending node's edges inside its cell
  lead to pending nodes, unmarked, and its edges out of the cell lead back to the ordinary
  nodes and carry the mark. So the mark of such an edge counts only once the robot has left
  the cell: no accepting cycle stays in it.

The edges keep their weights, so a path of this product costs what its image in the
triangles' product costs (``origin`` maps each node to the node it copies). Every accepting
lasso here is an accepting lasso of the triangles' product with no turning back and no cycle
inside a cell whose stay is too narrow; conversely such a lasso of the triangles' product
is one here once its prefix runs one more lap of its cycle (the way into the cell of the
cycle's first node, or its pending state, may differ between the prefix's arrival and the
cycle's return). The largest width of a lasso here is therefore the true largest
disturbance the cells support, and a plan found here passes the control stage's checks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tlmpc.abstraction.model import IntArray
from tlmpc.planning.product import SLOTS, BoolArray, Product
from tlmpc.planning.search import Graph


@dataclass(frozen=True, slots=True)
class CellProduct:
    """The product on cells and, per node of it, the node of the triangles' product it
    copies."""

    product: Product
    origin: IntArray


def cell_product(
    product: Product, cell_of: IntArray, stays_ok: BoolArray | None = None
) -> CellProduct:
    """``product`` (over a mesh whose triangles lie in the cells ``cell_of``) with the way
    into each cell in its nodes and, with ``stays_ok`` (per triangle: its cell's stay is
    realisable), the pending acceptance in the cells whose stay is not (see the module doc)."""
    entered = _with_entries(product, cell_of)
    if stays_ok is None:
        return entered
    return _with_pending(entered, product.num_automaton_states, cell_of, stays_ok)


def _node_cells(num_nodes: int, nq: int, cell_of: IntArray) -> IntArray:
    cells: IntArray = np.asarray(cell_of, dtype=np.int64)[np.arange(num_nodes) // nq // SLOTS]
    return cells


def _with_entries(product: Product, cell_of: IntArray) -> CellProduct:
    graph = product.graph
    n = graph.num_nodes
    nq = product.num_automaton_states
    node_cell = _node_cells(n, nq, cell_of)
    count = int(node_cell.max()) + 1 if n else 0
    sources = graph.sources.astype(np.int64)
    targets = graph.targets.astype(np.int64)
    here, there = node_cell[sources], node_cell[targets]
    crossing = here != there
    # The ways into each cell (cell, from), sorted: way 0 of a cell is the start, way k >= 1
    # the k-th of its pairs.
    keys = np.unique(there[crossing] * count + here[crossing])
    into, source_cell = keys // max(count, 1), keys % max(count, 1)
    first_way = np.searchsorted(into, np.arange(count))  # a cell's first pair in ``keys``
    ways = 1 + np.bincount(into, minlength=count)  # per cell
    copies = ways[node_cell]  # per node
    # copy k >= 1 of node x is n + extra[x] + k - 1 (node by node, ways in order)
    extra = np.concatenate([[0], np.cumsum(copies - 1)[:-1]]).astype(np.int64)
    total = n + int((copies - 1).sum())

    def node_id(x: IntArray, way: IntArray) -> IntArray:
        ids: IntArray = np.where(way == 0, x, n + extra[x] + way - 1)
        return ids

    def way_from(cell: IntArray, way: IntArray) -> IntArray:
        """The cell a way in comes from (-1: the start)."""
        index = np.minimum(first_way[cell] + way - 1, max(len(keys) - 1, 0))
        found: IntArray = np.where(way == 0, -1, source_cell[index] if len(keys) else -1)
        return found

    # every edge once per way into its tail's cell
    repeats = copies[sources]
    edge = np.repeat(np.arange(graph.nnz), repeats)
    way = np.arange(len(edge)) - np.repeat(np.cumsum(repeats) - repeats, repeats)
    tail, head = sources[edge], targets[edge]
    tail_cell, head_cell = here[edge], there[edge]
    moving = tail_cell != head_cell
    # a move into another cell: not from a copy entered from that cell
    keep = ~moving | (way_from(tail_cell, way) != head_cell)
    edge, way, tail, head, moving = edge[keep], way[keep], tail[keep], head[keep], moving[keep]
    head_way = way.copy()
    if moving.any():
        pair = head_cell[keep][moving] * count + tail_cell[keep][moving]
        head_way[moving] = np.searchsorted(keys, pair) - first_way[head_cell[keep][moving]] + 1
    expanded, order = Graph.from_edges(
        node_id(tail, way), node_id(head, head_way), graph.weights[edge], total
    )
    origin = np.empty(total, dtype=np.int64)
    origin[:n] = np.arange(n)
    more = np.flatnonzero(copies > 1)
    owners = np.repeat(more, copies[more] - 1)
    origin[n:] = owners
    return CellProduct(
        product=Product(
            graph=expanded,
            accepting=product.accepting[edge][order],
            stutter_accepting=product.stutter_accepting[origin],
            initial=product.initial,
            num_automaton_states=nq,
            num_nodes=total,
        ),
        origin=origin,
    )


def _with_pending(
    entered: CellProduct, nq: int, cell_of: IntArray, stays_ok: BoolArray
) -> CellProduct:
    product, origin = entered.product, entered.origin
    graph = product.graph
    n = graph.num_nodes
    triangle = origin // nq // SLOTS
    node_cell = np.asarray(cell_of, dtype=np.int64)[triangle]
    narrow = ~np.asarray(stays_ok, dtype=bool)[triangle]  # per node: its cell's stay is not
    sources = graph.sources.astype(np.int64)
    targets = graph.targets.astype(np.int64)
    inside = node_cell[sources] == node_cell[targets]
    deferred = narrow[sources] & inside & product.accepting
    if not deferred.any():
        return entered  # no accepting edge inside such a cell: nothing to defer
    pending = np.flatnonzero(narrow)
    pending_id = np.full(n, -1, dtype=np.int64)
    pending_id[pending] = n + np.arange(len(pending))
    # the ordinary edges, an accepting one inside a narrow cell leading to the pending head
    heads = np.where(deferred, pending_id[targets], targets)
    marks = product.accepting & ~deferred
    # the pending nodes' edges: inside the cell to pending nodes, out of it marked
    out = np.flatnonzero(narrow[sources])
    pending_heads = np.where(inside[out], pending_id[targets[out]], targets[out])
    expanded, order = Graph.from_edges(
        np.concatenate([sources, pending_id[sources[out]]]),
        np.concatenate([heads, pending_heads]),
        np.concatenate([graph.weights, graph.weights[out]]),
        n + len(pending),
    )
    accepting = np.concatenate([marks, ~inside[out]])[order]
    return CellProduct(
        product=Product(
            graph=expanded,
            accepting=accepting,
            stutter_accepting=np.concatenate(
                [product.stutter_accepting, np.zeros(len(pending), dtype=bool)]
            ),
            initial=product.initial,
            num_automaton_states=nq,
            num_nodes=n + len(pending),
        ),
        origin=np.concatenate([origin, origin[pending]]),
    )
