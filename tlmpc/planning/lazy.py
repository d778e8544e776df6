"""The product of the transition system and the automaton, expanded on demand.

:class:`LazyProduct` is the graph :func:`tlmpc.planning.product.build_product` builds, with
the same node numbers (``(t * SLOTS + s) * Q + q``), edges, weights and acceptance marks, but
nothing per product node is stored: only the transition system's moves (per triangle and
slot) and the automaton's successor tables per kind of move.  :meth:`LazyProduct.expand`
gives the edges out of any set of nodes, so a search guided towards its goal
(:mod:`tlmpc.planning.guided`) touches only the part of the product it needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.model import Automaton
from tlmpc.planning.boundary import POINT, StartCell
from tlmpc.planning.product import (
    SLOTS,
    STUTTER_COST,
    BoolArray,
    Successors,
    edge_midpoints,
    initial_nodes,
    move_table,
    stutter_cells,
)
from tlmpc.planning.timing import MoveTimes


@dataclass(frozen=True, slots=True)
class Edges:
    """A batch of product edges: tails, heads, weights and acceptance marks."""

    tails: IntArray
    heads: IntArray
    weights: FloatArray
    accepting: BoolArray


@dataclass(frozen=True, slots=True, kw_only=True)
class LazyProduct:
    """The product graph as tables (see the module doc).

    Moves of the transition system are in CSR order by source cell (``move_indptr``); a
    move's *kind* (compact ids) says which letters it reads, ``successor[kind, q, j]`` is the
    ``j``-th automaton successor of ``q`` over it (-1 past the last) and ``marked`` whether
    that edge accepts.  Stutter steps read the triangle's own letter class again:
    ``stutter_successor[class, q, j]`` lists the successors other than ``q`` itself and
    ``stutter_accepts[class, q]`` whether staying in ``q`` accepts.
    """

    num_states: int
    num_cells: int
    move_indptr: IntArray
    move_target: IntArray  # the cell entered
    move_weight: FloatArray
    move_kind: IntArray  # compact kind id
    successor: IntArray  # (kinds, Q, J)
    marked: BoolArray  # (kinds, Q, J)
    kind_class: IntArray  # per kind: the letter class of the triangle it enters
    kind_left: BoolArray  # (kinds, classes): some move of the kind leaves a triangle of the class
    triangle_class: IntArray  # per triangle: its letter's class
    cell_class: IntArray  # per cell: its triangle's letter class (-1: no stutter there)
    stutter_successor: IntArray  # (classes, Q, J')
    stutter_marked: BoolArray  # (classes, Q, J')
    stutter_accepts: BoolArray  # (classes, Q)
    position: FloatArray  # (cells, 2): the entry edge's midpoint, the start point in slot 3
    initial: IntArray

    @property
    def num_nodes(self) -> int:
        """Number of product nodes (reached or not)."""
        return self.num_cells * self.num_states

    def expand(self, nodes: IntArray, base: IntArray | None = None, *, marks: bool = True) -> Edges:
        """Every product edge out of ``nodes``: per node its moves (each with its automaton
        successors), then its stutter edges; (tail, head) pairs are distinct.  With
        ``base``, node ``k`` stands for ``base[k] + nodes[k]`` in tails and heads (searches
        that run side by side, each in its own copy of the node numbers).  Without
        ``marks`` the acceptance marks are not looked up (``accepting`` is empty): a search
        that reads none of them saves their gathers."""
        nq = self.num_states
        cell, state = np.divmod(nodes, nq)
        starts = self.move_indptr[cell]
        counts = self.move_indptr[cell + 1] - starts
        ends = np.cumsum(counts)
        total = int(ends[-1]) if len(ends) else 0
        moves = np.repeat(starts - ends + counts, counts) + np.arange(total, dtype=np.int64)
        shift = None if base is None else np.repeat(base, counts)
        if base is not None:
            nodes = nodes + base
        tail = np.repeat(nodes, counts)
        q = np.repeat(state, counts)
        kind = self.move_kind[moves]
        tails: list[IntArray] = []
        heads: list[IntArray] = []
        weights: list[FloatArray] = []
        accepting: list[BoolArray] = []
        for j in range(self.successor.shape[2]):
            following = self.successor[kind, q, j]
            ok = following >= 0
            tails.append(tail[ok])
            taken = moves[ok]
            head = self.move_target[taken] * nq + following[ok]
            heads.append(head if shift is None else head + shift[ok])
            weights.append(self.move_weight[taken])
            if marks:
                accepting.append(self.marked[kind[ok], q[ok], j])
        staying = self.cell_class[cell] >= 0
        stay_nodes, stay_q = nodes[staying], state[staying]
        stay_class = self.cell_class[cell[staying]]
        for j in range(self.stutter_successor.shape[2]):
            following = self.stutter_successor[stay_class, stay_q, j]
            ok = following >= 0
            stutter_tails = stay_nodes[ok]
            tails.append(stutter_tails)
            heads.append(stutter_tails - stay_q[ok] + following[ok])
            weights.append(np.full(len(stutter_tails), STUTTER_COST))
            if marks:
                accepting.append(self.stutter_marked[stay_class[ok], stay_q[ok], j])
        return Edges(
            tails=np.concatenate(tails) if tails else np.zeros(0, dtype=np.int64),
            heads=np.concatenate(heads) if heads else np.zeros(0, dtype=np.int64),
            weights=np.concatenate(weights) if weights else np.zeros(0),
            accepting=np.concatenate(accepting) if accepting else np.zeros(0, dtype=bool),
        )

    def stays_accepting(self, nodes: IntArray) -> BoolArray:
        """Whether each node's stutter loop accepts (the plan may end there, staying)."""
        nq = self.num_states
        cls = self.cell_class[nodes // nq]
        accepts: BoolArray = (cls >= 0) & self.stutter_accepts[np.maximum(cls, 0), nodes % nq]
        return accepts

    def path_weights(self, nodes: list[int]) -> list[float]:
        """The weights of the edges ``nodes[k] -> nodes[k + 1]`` (KeyError when missing)."""
        if len(nodes) < 2:
            return []
        path = np.asarray(nodes, dtype=np.int64)
        tails, heads = path[:-1], path[1:]
        # Every edge out of every tail, then per step the edge to the next node.
        edges = self.expand(np.unique(tails))
        key = edges.tails * self.num_nodes + edges.heads
        sort = np.argsort(key, kind="stable")
        wanted = tails * self.num_nodes + heads
        at = np.searchsorted(key[sort], wanted)
        at = np.minimum(at, len(key) - 1)
        hit = key[sort][at] == wanted
        if not hit.all():
            step = int(np.flatnonzero(~hit)[0])
            raise KeyError((int(tails[step]), int(heads[step])))
        weights: list[float] = edges.weights[sort][at].tolist()
        return weights


def lazy_product(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    allowed: BoolArray,
    start_point: tuple[float, float],
    metric: str,
    starts: tuple[StartCell, ...] | None = None,
    convention: str = "right",
    start_label: tuple[str, ...] = (),
    bounces: bool = False,
    realisable: tuple[BoolArray, BoolArray] | None = None,
    times: MoveTimes | None = None,
) -> LazyProduct:
    """The product :func:`~tlmpc.planning.product.build_product` would build from the same
    arguments, as tables (nothing per product node).  With ``realisable`` a triangle without
    a stay field has no stutter at all (the built product drops only its final stays: the
    tables keep stutter per letter class, so this one is more restrictive, still sound)."""
    table = move_table(
        abstraction,
        automaton,
        allowed=allowed,
        start_point=start_point,
        metric=metric,
        starts=starts,
        convention=convention,
        bounces=bounces,
        realisable=realisable,
        times=times,
    )
    starts, classes, tri_class = table.starts, table.classes, table.tri_class
    moves, weight, raw_kind = table.moves, table.weight, table.kind
    closed = convention == "closed"
    successors = Successors(classes, automaton)
    kinds = successors.of_moves(raw_kind)
    compact = np.zeros(max(kinds, default=0) + 1, dtype=np.int64)
    compact[kinds] = np.arange(len(kinds))
    move_kind = compact[raw_kind]
    nq = automaton.num_states
    successor, marked = _padded([successors.by_kind[k] for k in kinds], nq)
    kind_class = np.zeros(len(kinds), dtype=np.int64)
    kind_class[move_kind] = tri_class[moves.target // SLOTS]
    kind_left = np.zeros((len(kinds), len(classes.rows)), dtype=bool)
    kind_left[move_kind, tri_class[moves.source // SLOTS]] = True
    cells = abstraction.num_triangles * SLOTS
    stay_cell, stay_class = stutter_cells(abstraction, allowed, starts, tri_class)
    cell_class = np.full(cells, -1, dtype=np.int64)
    cell_class[stay_cell] = stay_class
    if realisable is not None:
        cell_class[~np.repeat(realisable[1], SLOTS)] = -1
    num_classes = len(classes.rows)
    stutter_tables: list[list[list[tuple[int, bool]]]] = []
    stutter_accepts = np.zeros((num_classes, nq), dtype=bool)
    for cls in range(num_classes):
        per_state = []
        for q in range(nq):
            found = successors.after(cls, q)
            stutter_accepts[cls, q] = found.get(q, False)
            per_state.append([(q2, mark) for q2, mark in found.items() if q2 != q])
        stutter_tables.append(per_state)
    stutter_successor, stutter_marked = _padded(stutter_tables, nq)
    position = np.empty((abstraction.num_triangles, SLOTS, 2))
    position[:, :3, :] = edge_midpoints(abstraction)
    position[:, 3, :] = start_point
    start_letter = tuple(sorted({*start_label, POINT})) if closed else None
    return LazyProduct(
        num_states=nq,
        num_cells=cells,
        move_indptr=np.concatenate(
            [[0], np.cumsum(np.bincount(moves.source, minlength=cells))]
        ).astype(np.int64),
        move_target=moves.target,
        move_weight=weight,
        move_kind=move_kind,
        successor=successor,
        marked=marked,
        kind_class=kind_class,
        kind_left=kind_left,
        triangle_class=tri_class,
        cell_class=cell_class,
        stutter_successor=stutter_successor,
        stutter_marked=stutter_marked,
        stutter_accepts=stutter_accepts,
        position=position.reshape(-1, 2),
        initial=initial_nodes(automaton, classes, tri_class, allowed, starts, start_letter),
    )


def _padded(tables: list[list[list[tuple[int, bool]]]], nq: int) -> tuple[IntArray, BoolArray]:
    """(len(tables), nq, J) successor states (-1 past the last) and marks."""
    width = max((len(found) for per_state in tables for found in per_state), default=0)
    successor = np.full((len(tables), nq, max(width, 1)), -1, dtype=np.int64)
    marked = np.zeros(successor.shape, dtype=bool)
    for k, per_state in enumerate(tables):
        for q, found in enumerate(per_state):
            for j, (q_next, mark) in enumerate(found):
                successor[k, q, j] = q_next
                marked[k, q, j] = mark
    return successor, marked
