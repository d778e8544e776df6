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
from typing import Any

import numpy as np
import numpy.typing as npt

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.guards import successor_table
from tlmpc.automata.model import Automaton
from tlmpc.base.content import ContentEquality
from tlmpc.planning.boundary import POINT, StartCell, crossing_letter, start_cells
from tlmpc.planning.search import Graph
from tlmpc.planning.timing import MoveTimes, move_time_table

SLOTS = 4  # three edges, and "no entry edge yet" for the start
START_SLOT = 3
#: Weight of a stutter step: the searches need positive weights, and stutter is free.
STUTTER_COST = 1e-9
#: Node and edge numbers up to this count are held in 32 bits (half the memory of a product's
#: index arrays: the numbers 0 .. 2**31 - 1); beyond it, in 64 bits.
INT32_LIMIT = 2**31

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


def index_dtype(count: int) -> type[np.signedinteger[Any]]:
    """The integer type for the numbers ``0 .. count - 1``: 32 bits while they fit, else 64.

    A product's node numbers (and its cells and moves, numbered below its node count) and
    its edge positions use it, so a product too large for 32-bit numbers is built the same,
    only larger: nothing is computed in 32 bits that could pass 2**31 - 1.
    """
    return np.int32 if count <= INT32_LIMIT else np.int64


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


def move_lengths(abstraction: Abstraction, start_point: tuple[float, float]) -> FloatArray:
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
    times: MoveTimes | None = None,
) -> Product:
    """The product graph restricted to ``allowed`` triangles.

    ``metric`` is ``"length"`` (Euclidean length through the crossed edges' midpoints,
    starting at ``start_point``), ``"hops"`` (one per move) or ``"time"`` (seconds per move,
    ``times``: :mod:`tlmpc.planning.timing`).  ``bounces=True`` also allows
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
    nq = automaton.num_states
    size = abstraction.num_triangles * SLOTS * nq
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
        # moves are numbered on the (triangle, slot, exit) grid, cells below the node count
        dtype=index_dtype(max(size, abstraction.num_triangles * SLOTS * 3)),
    )
    starts, classes, tri_class = table.starts, table.classes, table.tri_class
    moves, weight, move_kind = table.moves, table.weight, table.kind
    closed = convention == "closed"
    successors = Successors(classes, automaton)
    stay_cell, stay_class = stutter_cells(abstraction, allowed, starts, tri_class)
    stutter_accepting = np.zeros(size, dtype=bool)
    stay_edges = successors.stutter_edges(
        stay_cell,
        stay_class,
        stutter_accepting,
        stay_ok=None if realisable is None else realisable[1],
    )
    graph, accepting = _product_edges(moves, move_kind, weight, successors, stay_edges)
    start_letter = tuple(sorted({*start_label, POINT})) if closed else None
    return Product(
        graph=graph,
        accepting=accepting,
        stutter_accepting=stutter_accepting,
        initial=initial_nodes(automaton, classes, tri_class, allowed, starts, start_letter),
        num_automaton_states=nq,
        num_nodes=size,
    )


@dataclass(frozen=True, slots=True)
class MoveTable:
    """What the built and the lazy product share: the start cells, the letter classes (and
    each triangle's), the moves of D with their weights and kinds (a letter class, or under
    the closed convention a crossing kind, see :func:`crossing_move_kinds`)."""

    starts: tuple[StartCell, ...]
    classes: LetterClasses
    tri_class: IntArray
    moves: _Moves
    weight: FloatArray
    kind: IntArray


def move_table(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    allowed: BoolArray,
    start_point: tuple[float, float],
    metric: str,
    starts: tuple[StartCell, ...] | None,
    convention: str,
    bounces: bool,
    realisable: tuple[BoolArray, BoolArray] | None,
    times: MoveTimes | None = None,
    dtype: type[np.signedinteger[Any]] = np.int64,
) -> MoveTable:
    """The moves of the product over ``abstraction`` and ``automaton`` (arguments as for
    :func:`build_product`), their numbers (cells, exits, kinds) as ``dtype``: the built
    product's :func:`index_dtype` of its node count (the lazy product multiplies cells by
    automaton states in 64 bits)."""
    if starts is None:
        starts = start_cells(abstraction, start_point)
    classes = LetterClasses.of(automaton, list(abstraction.letters))
    tri_class = classes.letter_class[abstraction.letter_of]
    moves = ts_moves(
        abstraction, allowed, starts, bounces=bounces, realisable=realisable, dtype=dtype
    )
    weight = move_weights(abstraction, moves, start_point, metric, times)
    if convention == "closed":
        kind = crossing_move_kinds(abstraction, automaton, classes, tri_class, moves)
    else:
        kind = tri_class[abstraction.neighbors].reshape(-1)[moves.exit]
    return MoveTable(starts, classes, tri_class, moves, weight, kind.astype(dtype, copy=False))


Row = list[tuple[tuple[int, int], ...]]


@dataclass(slots=True)
class LetterClasses:
    """Letters with the same projection on the automaton's propositions behave the same: the
    successor table shares one row between them.  A class per row, numbered by first
    occurrence (the table's letters first, then the rows :meth:`class_of` meets)."""

    rows: list[Row]
    index: dict[int, int]  # id of a row -> its class
    letter_class: IntArray  # per letter of the table the classes were made from

    @staticmethod
    def of(automaton: Automaton, letters: list[tuple[str, ...]]) -> LetterClasses:
        """The classes of ``letters``."""
        table = successor_table(automaton, letters)
        index: dict[int, int] = {}
        letter_class = np.array(
            [index.setdefault(id(row), len(index)) for row in table], dtype=np.int64
        )
        rows = list({id(row): row for row in table}.values())  # in order of first occurrence
        return LetterClasses(rows=rows, index=index, letter_class=letter_class)

    def class_of(self, row: Row) -> int:
        """The class of a row of a successor table, numbered anew if it is new."""
        key = id(row)
        if key not in self.index:
            self.index[key] = len(self.rows)
            self.rows.append(row)
        return self.index[key]


@dataclass(frozen=True, slots=True)
class _Moves:
    """The moves of D, ``(t, s) --i--> (n, s')`` with ``i != s`` unless bouncing, laid out on
    the (triangle, slot, exit) grid, whose flat order is the nodes' order: they come out
    sorted by source cell without a sort."""

    flat: IntArray  # (t * SLOTS + s) * 3 + i
    source: IntArray  # the cell t * SLOTS + s
    exit: IntArray  # t * 3 + i
    target: IntArray  # the cell entered, n * SLOTS + s'
    exit_ok: BoolArray  # (m, 3): edge i of t leads from an allowed triangle to another


def ts_moves(
    abstraction: Abstraction,
    allowed: BoolArray,
    starts: tuple[StartCell, ...],
    *,
    bounces: bool,
    realisable: tuple[BoolArray, BoolArray] | None = None,
    dtype: type[np.signedinteger[Any]] = np.int64,
) -> _Moves:
    """Every move of D between ``allowed`` triangles (and, with ``realisable``, only the
    moves the controllers realise), numbered in ``dtype``.  Per (t, i) arrays (m, 3) are
    computed once and read for every slot."""
    m = abstraction.num_triangles
    neighbors = abstraction.neighbors
    is_start = np.zeros(m, dtype=bool)
    blocked = np.zeros((m, 3), dtype=bool)
    for cell in starts:
        is_start[cell.triangle] = True
        blocked[cell.triangle, list(cell.blocked)] = True
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
    moves = np.flatnonzero(valid).astype(dtype, copy=False)
    move_exit = moves // (SLOTS * 3) * 3 + moves % 3
    entered = (neighbors * SLOTS + entry_slots(neighbors)).reshape(-1).astype(dtype, copy=False)
    return _Moves(
        flat=moves,
        source=moves // 3,
        exit=move_exit,
        target=entered[move_exit],
        exit_ok=exit_ok,
    )


def entry_slots(neighbors: IntArray) -> IntArray:
    """(m, 3): the slot of t among the neighbours of its i-th neighbour (garbage where
    there is none).  Two comparisons: argmax over a 3-wide boolean axis is slow."""
    back = neighbors[np.maximum(neighbors, 0)]
    own = np.arange(len(neighbors), dtype=np.int64)[:, None]
    slot: IntArray = np.where(back[:, :, 0] == own, 0, np.where(back[:, :, 1] == own, 1, 2))
    return slot


def move_weights(
    abstraction: Abstraction,
    moves: _Moves,
    start_point: tuple[float, float],
    metric: str,
    times: MoveTimes | None = None,
) -> FloatArray:
    """Each move's weight: one under ``"hops"``, its seconds under ``"time"``
    (:func:`~tlmpc.planning.timing.move_time_table` of ``times``), else its length
    (:func:`move_lengths`)."""
    if metric == "hops":
        return np.ones(len(moves.flat))
    grid = move_weight_grid(abstraction, start_point, metric, times)
    weights: FloatArray = grid.reshape(-1)[moves.flat]
    return weights


def move_weight_grid(
    abstraction: Abstraction,
    start_point: tuple[float, float],
    metric: str,
    times: MoveTimes | None = None,
) -> FloatArray:
    """(m, SLOTS, 3): the weight of every move of D on the (triangle, slot, exit) grid under
    ``"length"`` (replaced by ``times.measured`` where given) or ``"time"`` (which needs
    ``times``)."""
    lengths = move_lengths(abstraction, start_point)
    if metric != "time":
        # under "length", ``times`` (speed 1) may carry measured lengths of moves: the
        # channel's shortest path through them (tlmpc.pipeline.shortest)
        if times is not None and times.measured:
            return move_time_table(abstraction, lengths, times)
        return lengths
    if times is None:
        raise ValueError("the time metric needs the robot's speed (MoveTimes)")
    return move_time_table(abstraction, lengths, times)


def crossing_move_kinds(
    abstraction: Abstraction,
    automaton: Automaton,
    classes: LetterClasses,
    tri_class: IntArray,
    moves: _Moves,
) -> IntArray:
    """Each move's kind under the closed convention, which reads the crossing instant's
    letter (both sides' labels and the point marker) before the entered triangle's: kind
    ``(c + 1) * stride + k`` reads class ``c``, then ``k`` (see :class:`Successors`).
    The crossing letters' new classes are numbered before ``stride`` is fixed."""
    neighbors = abstraction.neighbors
    letters = list(abstraction.letters)
    count = len(letters)
    exit_kind = tri_class[neighbors].reshape(-1)  # (m * 3,): garbage where there is no exit
    exits = np.flatnonzero(moves.exit_ok)
    entered = neighbors.reshape(-1)[exits]
    pair = abstraction.letter_of[exits // 3] * count + abstraction.letter_of[entered]
    unique_pairs, pair_index = np.unique(pair, return_inverse=True)
    crossing = [
        crossing_letter(letters[key // count], letters[key % count])
        for key in unique_pairs.tolist()
    ]
    crossing_class = np.array(
        [classes.class_of(row) for row in successor_table(automaton, crossing)], dtype=np.int64
    ).reshape(-1)
    stride = len(classes.rows) + 1
    exit_kind[exits] += (crossing_class[pair_index.reshape(-1)] + 1) * stride
    move_kind: IntArray = exit_kind[moves.exit]
    return move_kind


def stutter_cells(
    abstraction: Abstraction,
    allowed: BoolArray,
    starts: tuple[StartCell, ...],
    tri_class: IntArray,
) -> tuple[IntArray, IntArray]:
    """The cells ``t * SLOTS + s`` that may stay (reading their own label again), and the
    class of that label: every entered slot of an allowed triangle, and the start slot of
    an allowed start triangle."""
    m = abstraction.num_triangles
    is_start = np.zeros(m, dtype=bool)
    for cell in starts:
        is_start[cell.triangle] = True
    stay_ok = np.empty((m, SLOTS), dtype=bool)
    stay_ok[:, :START_SLOT] = allowed[:, None] & (abstraction.neighbors >= 0)
    stay_ok[:, START_SLOT] = allowed & is_start
    stay_cell = np.flatnonzero(stay_ok)
    stay_class: IntArray = tri_class[stay_cell // SLOTS]
    return stay_cell, stay_class


#: Stutter edges of one automaton state ``q`` out of the cells ``stays``: the cells, ``q``,
#: and the successors (state, accepting).
StayEdges = tuple[IntArray, int, list[tuple[int, bool]]]


class Successors:
    """Automaton successors per kind of move (one letter class, or a crossing class and an
    entered class, see :func:`crossing_move_kinds`)."""

    def __init__(self, classes: LetterClasses, automaton: Automaton) -> None:
        self.rows = classes.rows
        self.stride = len(classes.rows) + 1
        self.full = (1 << automaton.num_acc) - 1
        self.num_states = automaton.num_states
        self.by_kind: dict[int, list[list[tuple[int, bool]]]] = {}

    def after(self, kind: int, q: int) -> dict[int, bool]:
        """Automaton successors of ``q`` over a move of ``kind`` (one or two letters).

        Parallel automaton edges would give duplicate pairs: one per successor, accepting if
        any is (every (node, node') pair is then unique).
        """
        found: dict[int, bool] = {}
        if kind >= self.stride:
            for q_mid, mask in self.rows[kind // self.stride - 1][q]:
                for q_next, mask_next in self.rows[kind % self.stride][q_mid]:
                    found[q_next] = found.get(q_next, False) or (mask | mask_next) == self.full
            return found
        for q_next, mask in self.rows[kind][q]:
            found[q_next] = found.get(q_next, False) or mask == self.full
        return found

    def of_moves(self, move_kind: IntArray) -> list[int]:
        """The kinds that occur among the moves (small integers: a count finds them), with
        their successors tabulated in :attr:`by_kind`."""
        kinds: list[int] = np.flatnonzero(np.bincount(move_kind)).tolist() if len(move_kind) else []
        for k in kinds:
            self.by_kind[k] = [list(self.after(k, q).items()) for q in range(self.num_states)]
        return kinds

    def stutter_edges(
        self,
        stay_cell: IntArray,
        stay_class: IntArray,
        stutter_accepting: BoolArray,
        *,
        stay_ok: BoolArray | None = None,
    ) -> list[StayEdges]:
        """The stutter edges per (class, state), in that order; marks in
        ``stutter_accepting`` the nodes whose stutter loop accepts (with ``stay_ok``, per
        triangle, only where a stay field exists: the run may end staying only there).
        Staying in the same state is the node itself: no edge."""
        nq = self.num_states
        classes = np.flatnonzero(np.bincount(stay_class)).tolist() if len(stay_cell) else []
        edges: list[StayEdges] = []
        for cls in classes:
            stays = stay_cell[stay_class == cls]
            final = stays if stay_ok is None else stays[stay_ok[stays // SLOTS]]
            for q in range(nq):
                found = self.after(cls, q)
                if found.get(q, False):
                    stutter_accepting[final * nq + q] = True
                others = [(q2, mark) for q2, mark in found.items() if q2 != q]
                if others:
                    edges.append((stays, q, others))
        return edges


def _product_edges(
    moves: _Moves,
    move_kind: IntArray,
    weight: FloatArray,
    successors: Successors,
    stay_edges: list[StayEdges],
) -> tuple[Graph, BoolArray]:
    """The product's edges written straight into CSR order, and their acceptance marks.

    A node's edges: its moves in exit order, each with its successors in turn, then its
    stutter edges.  Degrees first, then each edge's position, then one write per array;
    every pass handles one automaton state's edges (1-d arrays, no sort).
    """
    nq = successors.num_states
    cells = len(moves.exit_ok) * SLOTS
    size = cells * nq
    node_type = index_dtype(size)  # node numbers (the moves' cells are numbered alike)
    move_kinds = successors.of_moves(move_kind)
    by_kind = successors.by_kind
    # A cell's moves (at most three) are adjacent: a move's rank among them says which of
    # the one or two moves before it share its node.
    source = moves.source
    rank = np.zeros(len(source), dtype=np.int32)
    rank[1:] += source[1:] == source[:-1]
    rank[2:] += source[2:] == source[:-2]
    moves_of_cell = np.bincount(source, minlength=cells)

    def degrees(q: int) -> int | IntArray:
        """How many edges each move gives out of its node (cell, q): one number when every
        kind of move gives the same (one, for a complete deterministic automaton), else an
        array over the moves."""
        degree = np.zeros(max(move_kinds, default=0) + 1, dtype=np.int64)
        for k in move_kinds:
            degree[k] = len(by_kind[k][q])
        counts = {int(degree[k]) for k in move_kinds}
        if len(counts) <= 1:
            return counts.pop() if counts else 0
        per_move: IntArray = degree.take(move_kind)
        return per_move

    def offsets(q: int) -> npt.NDArray[np.signedinteger[Any]]:
        """Per move, how many edges of its node (cell, q) come before its own."""
        per_move = degrees(q)
        if isinstance(per_move, int):
            return rank * per_move
        offset = np.zeros(len(source), dtype=np.int64)
        offset[1:] = per_move[:-1] * (rank[1:] >= 1)
        offset[2:] += per_move[:-2] * (rank[2:] >= 2)
        return offset

    out_degree = np.empty((cells, nq), dtype=np.int32)  # a node's edges: a handful
    for q in range(nq):
        per_move = degrees(q)
        if isinstance(per_move, int):
            out_degree[:, q] = moves_of_cell * per_move
        else:
            out_degree[:, q] = np.bincount(source, weights=per_move, minlength=cells)
    # A node's stutter edges come after its moves.
    stutter_before: list[IntArray] = []
    for stays, q, found in stay_edges:
        stutter_before.append(out_degree[stays, q])
        out_degree[stays, q] += len(found)
    degree_of_node = out_degree.reshape(-1)
    nnz = int(degree_of_node.sum())
    indptr = np.zeros(size + 1, dtype=index_dtype(nnz + 1))
    np.cumsum(degree_of_node, out=indptr[1:])
    dst = np.empty(nnz, dtype=node_type)
    wgt = np.empty(nnz)
    acc = np.zeros(nnz, dtype=bool)
    move_node = source.astype(node_type, copy=False) * nq
    move_target = moves.target.astype(node_type, copy=False) * nq
    for q in range(nq):
        width = max((len(by_kind[k][q]) for k in move_kinds), default=0)
        if not width:
            continue
        first = indptr[move_node + q] + offsets(q)
        for j in range(width):
            # The j-th successor of q over each kind of move (-1: none), and its mark.
            following = np.full(max(move_kinds) + 1, -1, dtype=node_type)  # a state
            marked = np.zeros(len(following), dtype=bool)
            for k in move_kinds:
                if j < len(by_kind[k][q]):
                    following[k], marked[k] = by_kind[k][q][j]
            # Every move, or those whose kind has a j-th successor (a slice: no copies).
            rows: slice | IntArray = slice(None)
            if not (following[move_kinds] >= 0).all():
                rows = np.flatnonzero(following.take(move_kind) >= 0)
            at = first if j == 0 and isinstance(rows, slice) else first[rows] + j
            dst[at] = move_target[rows] + following.take(move_kind[rows])
            wgt[at] = weight[rows]
            if marked.any():
                acc[at] = marked.take(move_kind[rows])
    for (stays, q, found), before in zip(stay_edges, stutter_before, strict=True):
        node = stays * nq
        first = indptr[node + q] + before
        for j, (q_next, accepting) in enumerate(found):
            dst[first + j] = node + q_next
            wgt[first + j] = STUTTER_COST
            acc[first + j] = accepting
    return Graph(indptr=indptr, targets=dst, weights=wgt, num_nodes=size), acc


def initial_nodes(
    automaton: Automaton,
    classes: LetterClasses,
    tri_class: IntArray,
    allowed: BoolArray,
    starts: tuple[StartCell, ...],
    start_letter: tuple[str, ...] | None,
) -> IntArray:
    """Each allowed start triangle's start node after reading (``start_letter``, the start
    point's letter under the closed convention, then) its own label."""
    nq = automaton.num_states
    entry_states = [automaton.initial]
    if start_letter is not None:
        point_row = successor_table(automaton, [start_letter])[0]
        entry_states = list(dict.fromkeys(q for q, _ in point_row[automaton.initial]))
    found: set[int] = set()
    for cell in starts:
        if not allowed[cell.triangle]:
            continue
        row = classes.rows[int(tri_class[cell.triangle])]
        for q0 in entry_states:
            found.update((cell.triangle * SLOTS + START_SLOT) * nq + q for q, _ in row[q0])
    return np.array(sorted(found), dtype=np.int64)
