"""Lower bounds on the cost still to pay from a product node: the guided search's heuristic.

The bounds come from a small *region-level* graph.  Its nodes are pairs ``(q, c)``: the
automaton in state ``q``, and ``c`` the letter class of the last *landmark* triangle entered
(every letter class of the allowed triangles is a landmark but the most common one, the
*background*).  An edge reads one kind of move or a stutter step:

* from a triangle of ``c`` or of the background into one of those, or a stutter step: the
  landmark stays ``c``, and the edge costs nothing (the robot is in one of those: entering
  any other landmark would have made it the last);
* into a triangle of another landmark ``c'``: it costs ``delta(c, c')``, the least cost in
  the transition system alone (no automaton) from any cell of a ``c`` triangle to entering a
  ``c'`` triangle.

Every product path maps onto a path of this graph that costs no more (the region-level graph
has every automaton step the product has, and the product's path from the last ``c``
triangle to the ``c'`` one costs at least ``delta(c, c')``), so its least cost to a target is
a lower bound.  For a concrete node the first leg is bounded by ``D[c'](cell)``, the cost from
that very cell to entering a ``c'`` triangle (one multi-source search per landmark on the
transition system, backwards).  The distances of the transition system are those of the
product's own moves and weights (:class:`~tlmpc.planning.lazy.LazyProduct`), so the bounds
hold for whatever edge costs the product is given.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tlmpc.abstraction.model import FloatArray, IntArray
from tlmpc.planning.lazy import LazyProduct
from tlmpc.planning.product import SLOTS, BoolArray
from tlmpc.planning.search import Graph, distances

#: Bounds are scaled down by this factor: the searches add the same weights in other orders,
#: so a bound equal to the true cost could exceed it by a rounding error.
SAFETY = 1.0 - 1e-9


@dataclass(frozen=True, slots=True)
class RegionGraph:
    """The region-level graph of a lazy product (see the module doc), with the transition
    system's distances to each landmark."""

    classes: IntArray  # letter class of each local class index (background included)
    background: int  # local index of the background class
    landmarks: IntArray  # local indices of the landmarks
    cell_local: IntArray  # per cell: its triangle's local class (-1: not allowed)
    distance: FloatArray  # (cells, landmarks): cost from the cell to entering the landmark
    delta: FloatArray  # (local, local): region-to-region lower bound (0 from the background)
    entry: BoolArray  # per cell: entered from a triangle of another class (a boundary entry)
    delta_entry: FloatArray  # (local, local): as delta, from the entry cells of the region
    closure: BoolArray  # (local, Q, Q): states reached for free with that last landmark
    entering: list[tuple[int, IntArray, IntArray]]  # (landmark, from states, to states)
    scale: float  # weight per unit of Euclidean length, at least (for the straight bound)
    backwards: Graph  # the transition system's moves, reversed
    cells_of: _ClassCells  # every landmark's cells
    entered_cells_of: _ClassCells  # every landmark's boundary entry cells
    background_cells: BoolArray  # per cell: in a triangle of the background

    def distance_to(self, cells: IntArray) -> FloatArray:
        """Per cell: the transition system's least cost from it to any of ``cells``."""
        distance: FloatArray = distances(self.backwards, cells)
        return distance

    def region_minimum(self, per_cell: FloatArray, *, entered: bool = False) -> FloatArray:
        """Per local class: the least value over its cells (``entered``: over the landmark's
        boundary entry cells, where the robot is right after entering it; the background's
        over all its cells)."""
        least = np.full(len(self.classes), np.inf)
        least[self.landmarks] = (self.entered_cells_of if entered else self.cells_of).least(
            per_cell
        )
        # The background's cells are most of the map: one pass under a mask, not a gather.
        if len(least):
            least[self.background] = np.min(per_cell, where=self.background_cells, initial=np.inf)
        return least

    @property
    def num_states(self) -> int:
        """The automaton's number of states."""
        return int(self.closure.shape[1])


def region_graph(product: LazyProduct, allowed_cells: BoolArray) -> RegionGraph:
    """The region-level graph of ``product`` over the cells ``allowed_cells``."""
    nq = product.num_states
    cell_class = np.repeat(product.triangle_class, SLOTS)
    present = np.unique(cell_class[allowed_cells])
    counts = np.bincount(
        np.searchsorted(present, cell_class[allowed_cells]), minlength=len(present)
    )
    background = int(np.argmax(counts)) if len(present) else 0
    local_of = np.full(int(cell_class.max(initial=0)) + 1, -1, dtype=np.int64)
    local_of[present] = np.arange(len(present))
    cell_local = np.where(allowed_cells, local_of[cell_class], -1)
    landmarks = np.array([c for c in range(len(present)) if c != background], dtype=np.int64)
    cells = product.num_cells
    sources = np.repeat(np.arange(cells, dtype=np.int64), np.diff(product.move_indptr))
    backwards, _ = Graph.from_edges(product.move_target, sources, product.move_weight, cells)
    distance = _landmark_distances(backwards, cell_local, landmarks)
    # A boundary entry cell is entered by a move from a triangle of another local class: the
    # robot is in one right after the region-level graph's landmark changed to its class.
    entry = np.zeros(cells, dtype=bool)
    moved_from = cell_local[sources]
    entry[product.move_target[(moved_from != cell_local[product.move_target])]] = True
    entry &= cell_local >= 0
    count = len(present)
    delta = np.zeros((count, count))
    delta_entry = np.zeros((count, count))
    inside = _ClassCells(cell_local, landmarks, np.ones(cells, dtype=bool))
    entered = _ClassCells(cell_local, landmarks, entry)
    for index, landmark in enumerate(landmarks.tolist()):
        delta[landmarks, landmark] = inside.least(distance[:, index])
        delta_entry[landmarks, landmark] = entered.least(distance[:, index])
    kind_local = local_of[product.kind_class]
    closure = np.zeros((count, nq, nq), dtype=bool)
    entering: list[tuple[int, IntArray, IntArray]] = []
    free_kinds = kind_local == background
    for c in range(count):
        # While c is the last landmark the robot is in a triangle of c or of the background:
        # only moves leaving one of those (under the closed convention the crossing letter
        # tells, e.g. leaving a room reads it) into one of those are free.
        leaves = product.kind_left[:, present[c]] | product.kind_left[:, present[background]]
        step = np.zeros((nq, nq), dtype=bool)
        _mark(step, product.successor[(free_kinds | (kind_local == c)) & leaves])
        for stutter_class in {int(present[c]), int(present[background])}:
            _mark(step, product.stutter_successor[stutter_class][None])
        closure[c] = _reflexive_closure(step)
    for c in landmarks.tolist():
        into = np.zeros((nq, nq), dtype=bool)
        _mark(into, product.successor[kind_local == c])
        tails, heads = np.nonzero(into)
        entering.append((c, tails, heads))
    return RegionGraph(
        classes=present,
        background=background,
        landmarks=landmarks,
        cell_local=cell_local,
        distance=distance,
        delta=delta,
        entry=entry,
        delta_entry=delta_entry,
        closure=closure,
        entering=entering,
        scale=_straight_scale(product),
        backwards=backwards,
        cells_of=inside,
        entered_cells_of=entered,
        background_cells=cell_local == background,
    )


class _ClassCells:
    """The cells of each of some classes (among those ``pick`` holds), grouped so that the
    least of a per-cell value over each class is one pass."""

    def __init__(self, cell_local: IntArray, classes: IntArray, pick: BoolArray) -> None:
        cells = np.flatnonzero(pick & np.isin(cell_local, classes))
        order = np.argsort(cell_local[cells], kind="stable")
        self.cells = cells[order]
        grouped = cell_local[self.cells]
        self.starts = np.searchsorted(grouped, classes)  # classes ascending
        self.present = np.searchsorted(grouped, classes, side="right") > self.starts

    def least(self, per_cell: FloatArray) -> FloatArray:
        """Per class: the least value over its cells (inf for a class without cells)."""
        result = np.full(len(self.starts), np.inf)
        if len(self.cells):
            # The present classes' runs start strictly increasing, each ending where the
            # next begins (the last at the end).
            result[self.present] = np.minimum.reduceat(
                per_cell[self.cells], self.starts[self.present]
            )
        return result


def _mark(step: BoolArray, successor: IntArray) -> None:
    """Set ``step[q, q']`` for every successor ``q'`` of ``q`` in the (kinds, Q, J) table."""
    kinds, states, width = successor.shape
    q = np.broadcast_to(np.arange(states)[None, :, None], (kinds, states, width))
    ok = successor >= 0
    step[q[ok], successor[ok]] = True


def _reflexive_closure(step: BoolArray) -> BoolArray:
    """Reachability in zero or more steps."""
    reach = step | np.eye(len(step), dtype=bool)
    while True:
        # Squaring in single precision (BLAS): entries count paths, exact up to 2**24 states.
        wider = (reach.astype(np.float32) @ reach.astype(np.float32)) > 0
        if (wider == reach).all():
            return reach
        reach = wider


#: Cells per block when the landmark distances are put side by side (a block of 20 landmarks'
#: rows, 1.3 MB, stays in the cache while it is written).
_BLOCK = 8192


def _landmark_distances(backwards: Graph, cell_local: IntArray, landmarks: IntArray) -> FloatArray:
    """(cells, landmarks): the transition system's least cost from each cell to entering a
    triangle of each landmark (entered cells, not the start slot), inf where unreachable (a
    cell's row is what a bound reads at once)."""
    cells = backwards.num_nodes
    entered = np.ones(cells, dtype=bool)
    entered[SLOTS - 1 :: SLOTS] = False
    columns = [
        distances(backwards, np.flatnonzero(entered & (cell_local == landmark)))
        for landmark in landmarks.tolist()
    ]
    # Written a block of cells at a time: a column at a time, every write of the (cells,
    # landmarks) array lands on another cache line (a column is as long as the map).
    distance = np.empty((cells, len(landmarks)))
    for first in range(0, cells, _BLOCK):
        block = distance[first : first + _BLOCK]
        for index, column in enumerate(columns):
            block[:, index] = column[first : first + _BLOCK]
    return distance


def _straight_scale(product: LazyProduct) -> float:
    """The least weight per unit of straight-line length over the moves: a path's cost is at
    least this times the distance between its ends' positions."""
    sources = np.repeat(np.arange(product.num_cells, dtype=np.int64), np.diff(product.move_indptr))
    length = np.linalg.norm(
        product.position[product.move_target] - product.position[sources], axis=1
    )
    moving = length > 0
    if not moving.any():
        return 0.0
    return float((product.move_weight[moving] / length[moving]).min())


@dataclass(frozen=True, slots=True)
class CostToGo:
    """A lower bound on the cost from any product node to a target set with terminal costs:
    ``min(free[q, c], min over landmarks l of D[l](cell) + leg[q, c, l])`` for a node in
    state ``q`` in a cell of local class ``c``.

    With ``final`` the targets are the cells ``final`` measures the way to, in the states
    ``reach`` tells: a node whose free steps reach such a state is bounded by ``final`` at its
    own cell rather than by the region-level ``free``.  ``value[q, c]`` is the region-level
    cost right after entering landmark ``c`` in state ``q`` (the robot in one of its boundary
    entry cells), which :meth:`at_region` gives for ``entered=True``."""

    graph: RegionGraph
    free: FloatArray  # (Q, local)
    leg: FloatArray  # (Q, local, landmarks)
    value: FloatArray  # (Q, local): the cost to go right after entering the class
    anywhere: FloatArray  # (Q, local): the cost to go anywhere in the class or background
    final: FloatArray | None = None  # per cell: the cost still to pay in a target state
    reach: BoolArray | None = None  # (Q, local): free steps reach a target state

    def __call__(self, nodes: IntArray) -> FloatArray:
        """The bound at each node (inf: no target reachable; nodes of allowed cells)."""
        nq = self.graph.num_states
        cell, q = nodes // nq, nodes % nq
        c = self.graph.cell_local[cell]
        if self.final is not None and self.reach is not None:
            bound = np.where(self.reach[q, c], self.final[cell], np.inf)
        else:
            bound = self.free[q, c]
        return _via_landmarks(self.graph, cell, bound, self.leg[q, c])

    def at_region(self, q: int, c: int, *, entered: bool = False) -> float:
        """The bound at the region-level node ``(q, c)``: anywhere in ``c`` or the
        background with ``c`` the last landmark, or with ``entered`` right after entering
        landmark ``c`` (in one of its boundary entry cells)."""
        return float(self.value[q, c] if entered else self.anywhere[q, c])


def _via_landmarks(
    graph: RegionGraph, cell: IntArray, bound: FloatArray, leg: FloatArray
) -> FloatArray:
    """``bound`` lowered to the way through the next landmark entered (``leg``: per node,
    the cost after entering each landmark), scaled by :data:`SAFETY`."""
    if len(graph.landmarks):
        through = np.take(graph.distance, cell, axis=0)
        through += leg
        # The least over the landmarks down the columns of the sums laid out a landmark per
        # row: numpy's minimum along a short last axis runs a loop per node, several times
        # slower than the transposed copy and one elementwise pass per landmark.
        bound = np.minimum(bound, np.ascontiguousarray(through.T).min(axis=0))
    result: FloatArray = bound * SAFETY
    return result


@dataclass(frozen=True, slots=True)
class StackedCostToGo:
    """Several :class:`CostToGo` to cells (:func:`cost_to_go_to_cells`) of one graph, each
    node bounded by its own one's: the same values as calling each on its nodes, in one
    pass over all of them (searches side by side bound their nodes at once)."""

    graph: RegionGraph
    leg: FloatArray  # (K, Q, local, landmarks)
    final: FloatArray  # (K, cells)
    reach: BoolArray  # (K, Q, local)

    @staticmethod
    def of(bounds: Sequence[CostToGo]) -> StackedCostToGo:
        """The bounds stacked (each with a ``final`` and ``reach``, over the same graph)."""
        finals = [b.final for b in bounds if b.final is not None]
        reaches = [b.reach for b in bounds if b.reach is not None]
        if len(finals) < len(bounds) or len(reaches) < len(bounds):
            raise ValueError("only bounds to cells stack")
        legs = [b.leg for b in bounds]
        if len(bounds) == 1:  # views, not a copy of the per-cell array
            return StackedCostToGo(
                bounds[0].graph, legs[0][None], finals[0][None], reaches[0][None]
            )
        return StackedCostToGo(bounds[0].graph, np.stack(legs), np.stack(finals), np.stack(reaches))

    def __call__(self, which: IntArray, nodes: IntArray) -> FloatArray:
        """The bound at each node by the ``which``-th bound."""
        nq = self.graph.num_states
        cell, q = nodes // nq, nodes % nq
        c = self.graph.cell_local[cell]
        bound = np.where(self.reach[which, q, c], self.final[which, cell], np.inf)
        return _via_landmarks(self.graph, cell, bound, self.leg[which, q, c])


def cost_to_go_to_cells(graph: RegionGraph, state: int, final: FloatArray) -> CostToGo:
    """A bound on the cost from any node to a node in ``state`` at a cell ``final``
    measures the way to (per cell: the transition system's least cost from it)."""
    nq = graph.num_states
    terminal = np.full((nq, len(graph.classes)), np.inf)
    terminal[state, :] = graph.region_minimum(final)
    terminal_entered = np.full_like(terminal, np.inf)
    terminal_entered[state, :] = graph.region_minimum(final, entered=True)
    bound = cost_to_go(graph, terminal, terminal_entered)
    reach = graph.closure[:, :, state].T  # (Q, local)
    return dataclasses.replace(bound, final=final, reach=reach)


def cost_to_go(
    graph: RegionGraph, terminal: FloatArray, terminal_entered: FloatArray | None = None
) -> CostToGo:
    """The least region-level cost to a node ``(q, c)`` plus its ``terminal[q, c]`` (inf:
    not a target), as a bound on concrete nodes (see :class:`CostToGo`).
    ``terminal_entered`` (at least ``terminal``) may tell more of a target reached right
    after entering landmark ``c``.

    Bellman-Ford on the region-level graph: with nonnegative costs it settles within as many
    rounds as the graph has nodes, and in practice within the number of landmarks a cheapest
    path enters.  Every leg after the first starts where its landmark was entered, so it
    costs at least ``delta_entry``: the least cost from that landmark's boundary entry cells.
    """
    nq = graph.num_states
    count = len(graph.classes)
    closure = graph.closure
    # free[q, c]: a target reached without entering another landmark.
    free = _closure_min(closure, terminal)
    after_entry = free if terminal_entered is None else _closure_min(closure, terminal_entered)
    value = after_entry.copy()  # the region-level node's cost to go, right after entering
    landmarks = len(graph.landmarks)
    leg = np.full((nq, count, landmarks), np.inf)
    # The entering edges of every landmark in one table: (landmark index, tail, head).
    index = np.concatenate(
        [np.full(len(tails), k, dtype=np.int64) for k, (_, tails, _) in enumerate(graph.entering)]
        or [np.zeros(0, dtype=np.int64)]
    )
    tails = np.concatenate([t for _, t, _ in graph.entering] or [np.zeros(0, dtype=np.int64)])
    heads = np.concatenate([h for _, _, h in graph.entering] or [np.zeros(0, dtype=np.int64)])
    entered = graph.landmarks[index]
    into = graph.delta_entry[:, graph.landmarks]  # (local, landmarks)
    for _ in range(nq * count + 1):
        # Entering a landmark from state tail: the cheapest head's cost to go there.
        after = np.full((landmarks, nq), np.inf)
        np.minimum.at(after, (index, tails), value[heads, entered])
        leg = _masked_min(closure, after)
        updated = np.minimum(after_entry, (into[None, :, :] + leg).min(axis=2, initial=np.inf))
        if np.array_equal(updated, value):
            break
        value = updated
    # Anywhere in c: the next landmark is at least delta away (from any cell of c).
    away = (graph.delta[:, graph.landmarks][None, :, :] + leg).min(axis=2, initial=np.inf)
    return CostToGo(graph=graph, free=free, leg=leg, value=value, anywhere=np.minimum(free, away))


def _closure_min(closure: BoolArray, terminal: FloatArray) -> FloatArray:
    """(Q, local): the least ``terminal[q', c]`` over the states ``q'`` free steps with
    last landmark ``c`` reach from ``q``."""
    result: FloatArray = np.where(closure, terminal.T[:, None, :], np.inf).min(axis=2).T
    return result


def _masked_min(reach: BoolArray, cost: FloatArray) -> FloatArray:
    """(Q, local, landmarks): per state q, class c and landmark l, the least ``cost[l, q']``
    over the ``q'`` that ``reach[c, q]`` holds.

    A running minimum over the ``q'`` (those with a finite cost only): each adds its column
    to a 0 / inf mask of the (c, q) that reach it, so the temporary is as large as the result
    and each pass reads contiguous memory (a minimum over the last axis of a
    (landmarks, local, Q, Q) array was three times slower)."""
    landmarks, nq = cost.shape
    count = reach.shape[0]
    least = np.full((landmarks, count, nq), np.inf)
    columns = cost.T  # (Q', landmarks)
    for q_next in np.flatnonzero(np.isfinite(columns).any(axis=1)).tolist():
        mask = np.where(reach[:, :, q_next], 0.0, np.inf)  # (local, Q)
        np.minimum(least, mask[None] + columns[q_next][:, None, None], out=least)
    result: FloatArray = np.ascontiguousarray(least.transpose(2, 1, 0))
    return result
