"""The product of the transition system D (with stutter self-loops) and an automaton.

Built with numpy as a sparse graph, never one Python object per state.  A product node is
``((t * 4 + s) * Q + q)``: triangle ``t``, *entry slot* ``s`` (the edge of ``t`` the robot came
in through, ``3`` at the start), automaton state ``q``.  A move may leave ``t`` through any
edge but its entry edge, which is how no plan ever bounces: an affine field cannot enter a
triangle and leave it through the same edge.  Stuttering (staying in ``t``) keeps the slot.

The automaton reads the label of the triangle being entered (and of the start triangle first).
The start may lie in several triangles (on an edge or a vertex): each is an initial triangle,
and its edges through the start are blocked for its first move (see
:mod:`tlmpc.planning.boundary`).  Under the closed convention a move reads two letters: the
crossing instant's (both sides' labels and :data:`~tlmpc.planning.boundary.POINT`), then the
entered triangle's; the start reads its point letter before its triangle's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.guards import successor_table
from tlmpc.automata.model import Automaton
from tlmpc.base.content import ContentEquality
from tlmpc.planning.boundary import POINT, StartCell, crossing_letter, start_cells
from tlmpc.planning.search import Graph

SLOTS = 4  # three edges, and "no entry edge yet" for the start
START_SLOT = 3
#: Weight of a stutter step: the searches need positive weights, and stutter is free.
STUTTER_COST = 1e-9

BoolArray = npt.NDArray[np.bool_]


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Product(ContentEquality):
    """The product graph plus what the witness extraction needs."""

    graph: Graph  # weights
    accepting: BoolArray  # per edge of ``graph``: carries the mark
    stutter_accepting: BoolArray  # node whose stutter loop accepts
    initial: IntArray
    num_automaton_states: int
    num_nodes: int


def edge_midpoints(abstraction: Abstraction) -> FloatArray:
    """(m, 3, 2): midpoint of the edge opposite each vertex of each triangle."""
    return np.stack([_midpoints_along(abstraction, axis) for axis in range(2)], axis=2)


def _midpoints_along(abstraction: Abstraction, axis: int) -> FloatArray:
    """(m, 3): one coordinate of each edge's midpoint (that of :func:`edge_midpoints`)."""
    corner = abstraction.vertices[:, axis][abstraction.triangles]
    middle = np.empty(corner.shape)
    for i in range(3):
        middle[:, i] = (corner[:, (i + 1) % 3] + corner[:, (i + 2) % 3]) / 2.0
    return middle


def _move_lengths(abstraction: Abstraction, start_point: tuple[float, float]) -> FloatArray:
    """(m, SLOTS, 3): the weight of leaving each triangle through edge i after entering by
    edge s, from midpoint to midpoint (from the start point in the start slot).

    The same sum as ``sqrt(dx² + dy²)`` over the move's two points, computed once per
    unordered pair of edges: a difference negated squares to the same float.
    """
    x, y = (_midpoints_along(abstraction, axis) for axis in range(2))
    lengths = np.empty((len(x), SLOTS, 3))
    for i in range(3):
        a, b = (i + 1) % 3, (i + 2) % 3
        dx, dy = x[:, b] - x[:, a], y[:, b] - y[:, a]
        lengths[:, a, b] = lengths[:, b, a] = np.sqrt(dx * dx + dy * dy) + STUTTER_COST
        lengths[:, i, i] = STUTTER_COST  # a bounce: from a midpoint to itself
    dx, dy = x - start_point[0], y - start_point[1]
    lengths[:, START_SLOT, :] = np.sqrt(dx * dx + dy * dy) + STUTTER_COST
    return lengths


def build_product(
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
) -> Product:
    """The product graph restricted to ``allowed`` triangles.

    ``metric`` is ``"length"`` (Euclidean length through the crossed edges' midpoints,
    starting at ``start_point``) or ``"hops"`` (one per move).  ``bounces=True`` also allows
    leaving a triangle through its entry edge: that graph is stutter-equivalent to the face
    graph of the region arrangement, so it decides whether *any* continuous trajectory
    satisfies the task (see docs/planning.md); its bounces are realised by refinement.
    ``starts`` are the triangles containing the start point (with their blocked edges;
    by default those of ``start_point``);
    with ``convention="closed"`` the automaton reads crossing letters and, first of all,
    ``start_label`` (the regions whose closure holds the start point).  A blocked edge may be
    left at the first move only with ``bounces`` (it is a U-turn in that triangle).
    ``realisable`` restricts the moves (leave t by edge i, (m, 3)) and the final stays ((m,))
    to those the controllers realise (:func:`tlmpc.planning.robust.realisable`).
    """
    m = abstraction.num_triangles
    nq = automaton.num_states
    neighbors = abstraction.neighbors
    closed = convention == "closed"
    letters = list(abstraction.letters)
    table = successor_table(automaton, letters)
    # Letters with the same projection on the automaton's propositions behave the same: the
    # table shares one row between them.  A class per row, numbered by first occurrence.
    class_index: dict[int, int] = {}
    class_rows: list[list[tuple[tuple[int, int], ...]]] = []

    def class_of(row: list[tuple[tuple[int, int], ...]]) -> int:
        key = id(row)
        if key not in class_index:
            class_index[key] = len(class_rows)
            class_rows.append(row)
        return class_index[key]

    letter_class = np.array(
        [class_index.setdefault(id(row), len(class_index)) for row in table], dtype=np.int64
    )
    class_rows.extend({id(row): row for row in table}.values())  # in order of first occurrence
    tri_class = letter_class[abstraction.letter_of]
    if starts is None:
        starts = start_cells(abstraction, start_point)
    is_start = np.zeros(m, dtype=bool)
    blocked = np.zeros((m, 3), dtype=bool)
    for cell in starts:
        is_start[cell.triangle] = True
        blocked[cell.triangle, list(cell.blocked)] = True

    # --- moves of D: (t, s) --i--> (n, s') with i != s -------------------------------------
    # Laid out on the (triangle, slot, exit) grid, whose flat order is the nodes' order: the
    # moves come out sorted by source cell without a sort.  Per (t, i) arrays (m, 3) are
    # computed once and read for every slot.
    inside = np.append(allowed, False)  # index -1 (no neighbour) reads "not allowed"
    exit_ok = allowed[:, None] & inside[neighbors]
    if realisable is not None:
        exit_ok &= realisable[0]
    valid = np.empty((m, SLOTS, 3), dtype=bool)
    valid[:, :START_SLOT, :] = exit_ok[:, None, :]
    if not bounces:
        valid[:, :START_SLOT, :] &= ~np.eye(3, dtype=bool)
    # The start slot exists in start triangles only; their edges through the start point
    # are not left at t = 0 (that never enters the triangle).
    valid[:, START_SLOT, :] = exit_ok & is_start[:, None] & (~blocked | bounces)
    moves = np.flatnonzero(valid)  # (t * SLOTS + s) * 3 + i
    move_src = moves // 3  # the cell t * SLOTS + s
    move_exit = moves // (SLOTS * 3) * 3 + moves % 3  # t * 3 + i
    # The slot of t among n's neighbours (argmax over a 3-wide boolean axis is slow).
    back = neighbors[np.maximum(neighbors, 0)]
    own = np.arange(m, dtype=np.int64)[:, None]
    slot = np.where(back[:, :, 0] == own, 0, np.where(back[:, :, 1] == own, 1, 2))
    move_dst = (neighbors * SLOTS + slot).reshape(-1)[move_exit]
    if metric == "hops":
        weight = np.ones(len(moves))
    else:
        weight = _move_lengths(abstraction, start_point).reshape(-1)[moves]
    # A move's kind: the class of the entered triangle's letter, and under the closed
    # convention the class of the crossing instant's letter read before it.
    exit_kind = tri_class[neighbors].reshape(-1)  # (m * 3,): garbage where there is no exit
    if closed:
        count = len(letters)
        exits = np.flatnonzero(exit_ok)
        entered = neighbors.reshape(-1)[exits]
        pair = abstraction.letter_of[exits // 3] * count + abstraction.letter_of[entered]
        unique_pairs, pair_index = np.unique(pair, return_inverse=True)
        crossing = [
            crossing_letter(letters[key // count], letters[key % count])
            for key in unique_pairs.tolist()
        ]
        crossing_class = np.array(
            [class_of(row) for row in successor_table(automaton, crossing)], dtype=np.int64
        ).reshape(-1)
    # Kinds below ``stride`` read one letter; (c + 1) * stride + k reads c, then k.
    stride = len(class_rows) + 1
    if closed:
        exit_kind[exits] += (crossing_class[pair_index.reshape(-1)] + 1) * stride
    move_kind = exit_kind[move_exit]

    # --- stutter: (t, s) stays, reading its own label again --------------------------------
    stay_ok = np.empty((m, SLOTS), dtype=bool)
    stay_ok[:, :START_SLOT] = allowed[:, None] & (neighbors >= 0)
    stay_ok[:, START_SLOT] = allowed & is_start
    stay_cell = np.flatnonzero(stay_ok)  # t * SLOTS + s
    stay_class = tri_class[stay_cell // SLOTS]

    stutter_accepting = np.zeros(m * SLOTS * nq, dtype=bool)
    full = (1 << automaton.num_acc) - 1

    def successors_of(kind: int, q: int) -> dict[int, bool]:
        """Automaton successors of ``q`` over a move of ``kind`` (one or two letters).

        Parallel automaton edges would give duplicate pairs: one per successor, accepting if
        any is (every (node, node') pair is then unique).
        """
        found: dict[int, bool] = {}
        if kind >= stride:
            for q_mid, mask in class_rows[kind // stride - 1][q]:
                for q_next, mask_next in class_rows[kind % stride][q_mid]:
                    found[q_next] = found.get(q_next, False) or (mask | mask_next) == full
            return found
        for q_next, mask in class_rows[kind][q]:
            found[q_next] = found.get(q_next, False) or mask == full
        return found

    # Successors per kind that occurs (kinds are small integers: a count finds them).
    move_kinds = np.flatnonzero(np.bincount(move_kind)).tolist() if len(moves) else []
    stay_classes = np.flatnonzero(np.bincount(stay_class)).tolist() if len(stay_cell) else []
    move_succ = {k: [list(successors_of(k, q).items()) for q in range(nq)] for k in move_kinds}
    stay_succ: dict[int, list[list[tuple[int, bool]]]] = {}
    for cls in stay_classes:
        stays = stay_cell[stay_class == cls]
        # the run may end staying only where a stay field exists
        final = stays if realisable is None else stays[realisable[1][stays // SLOTS]]
        stay_succ[cls] = []
        for q in range(nq):
            found = successors_of(cls, q)
            if found.get(q, False):
                stutter_accepting[final * nq + q] = True
            # Staying in the same state is the node itself: no edge.
            stay_succ[cls].append([(q2, mark) for q2, mark in found.items() if q2 != q])

    # --- the edges, written straight into CSR order ----------------------------------------
    # A node's edges: its moves in exit order, each with its successors in turn, then its
    # stutter edges.  Degrees first, then each edge's position, then one write per array;
    # every pass handles one automaton state's edges (1-d arrays, no sort).
    cells = m * SLOTS
    size = cells * nq
    # A cell's moves (at most three) are adjacent in ``moves``: a move's rank among them
    # says which of the one or two moves before it share its node.
    rank = np.zeros(len(moves), dtype=np.int64)
    rank[1:] += move_src[1:] == move_src[:-1]
    rank[2:] += move_src[2:] == move_src[:-2]
    moves_of_cell = np.bincount(move_src, minlength=cells)

    def degrees(q: int) -> int | IntArray:
        """How many edges each move gives out of its node (cell, q): one number when every
        kind of move gives the same (one, for a complete deterministic automaton), else an
        array over the moves."""
        degree = np.zeros(max(move_kinds, default=0) + 1, dtype=np.int64)
        for k in move_kinds:
            degree[k] = len(move_succ[k][q])
        counts = {int(degree[k]) for k in move_kinds}
        if len(counts) <= 1:
            return counts.pop() if counts else 0
        per_move: IntArray = degree.take(move_kind)
        return per_move

    def offsets(q: int) -> IntArray:
        """Per move, how many edges of its node (cell, q) come before its own."""
        per_move = degrees(q)
        if isinstance(per_move, int):
            return rank * per_move
        offset = np.zeros(len(moves), dtype=np.int64)
        offset[1:] = per_move[:-1] * (rank[1:] >= 1)
        offset[2:] += per_move[:-2] * (rank[2:] >= 2)
        return offset

    out_degree = np.empty((cells, nq), dtype=np.int64)
    for q in range(nq):
        per_move = degrees(q)
        if isinstance(per_move, int):
            out_degree[:, q] = moves_of_cell * per_move
        else:
            out_degree[:, q] = np.bincount(move_src, weights=per_move, minlength=cells)
    # A node's stutter edges come after its moves.
    stay_edges: list[tuple[IntArray, int, IntArray, list[tuple[int, bool]]]] = []
    for cls in stay_classes:
        stays = stay_cell[stay_class == cls]
        for q in range(nq):
            if stay_succ[cls][q]:
                stay_edges.append((stays, q, out_degree[stays, q], stay_succ[cls][q]))
                out_degree[stays, q] += len(stay_succ[cls][q])
    indptr = np.zeros(size + 1, dtype=np.int64)
    np.cumsum(out_degree.reshape(-1), out=indptr[1:])
    nnz = int(indptr[-1])
    dst = np.empty(nnz, dtype=np.int64)
    wgt = np.empty(nnz)
    acc = np.zeros(nnz, dtype=bool)
    move_node = move_src * nq
    move_target = move_dst * nq
    for q in range(nq):
        width = max((len(move_succ[k][q]) for k in move_kinds), default=0)
        if not width:
            continue
        first = indptr[move_node + q] + offsets(q)
        for j in range(width):
            # The j-th successor of q over each kind of move (-1: none), and its mark.
            following = np.full(max(move_kinds) + 1, -1, dtype=np.int64)
            marked = np.zeros(len(following), dtype=bool)
            for k in move_kinds:
                if j < len(move_succ[k][q]):
                    following[k], marked[k] = move_succ[k][q][j]
            # Every move, or those whose kind has a j-th successor (a slice: no copies).
            rows: slice | IntArray = slice(None)
            if not (following[move_kinds] >= 0).all():
                rows = np.flatnonzero(following.take(move_kind) >= 0)
            at = first[rows] + j
            dst[at] = move_target[rows] + following.take(move_kind[rows])
            wgt[at] = weight[rows]
            if marked.any():
                acc[at] = marked.take(move_kind[rows])
    for stays, q, before, successors in stay_edges:
        node = stays * nq
        first = indptr[node + q] + before
        for j, (q_next, accepting) in enumerate(successors):
            dst[first + j] = node + q_next
            wgt[first + j] = STUTTER_COST
            acc[first + j] = accepting
    src = np.repeat(np.arange(size, dtype=np.int64), out_degree.reshape(-1))
    graph = Graph(indptr=indptr, sources=src, targets=dst, weights=wgt, num_nodes=size)
    accepting_edges = acc
    # Initial nodes: each start triangle after reading (the start point's letter, under the
    # closed convention, then) its own label.
    entry_states = [automaton.initial]
    if closed:
        point_row = successor_table(automaton, [tuple(sorted({*start_label, POINT}))])[0]
        entry_states = list(dict.fromkeys(q for q, _ in point_row[automaton.initial]))
    initial_nodes: set[int] = set()
    for cell in starts:
        if not allowed[cell.triangle]:
            continue
        row = class_rows[int(tri_class[cell.triangle])]
        for q0 in entry_states:
            initial_nodes.update((cell.triangle * SLOTS + START_SLOT) * nq + q for q, _ in row[q0])
    initial = np.array(sorted(initial_nodes), dtype=np.int64)
    return Product(
        graph=graph,
        accepting=accepting_edges,
        stutter_accepting=stutter_accepting,
        initial=initial,
        num_automaton_states=nq,
        num_nodes=size,
    )
