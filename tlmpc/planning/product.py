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

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.guards import successor_table
from tlmpc.automata.model import Automaton
from tlmpc.planning.boundary import POINT, StartCell, crossing_letter, start_cells
from tlmpc.planning.search import Graph

SLOTS = 4  # three edges, and "no entry edge yet" for the start
START_SLOT = 3
#: Weight of a stutter step: the searches need positive weights, and stutter is free.
STUTTER_COST = 1e-9

BoolArray = npt.NDArray[np.bool_]


@dataclass(frozen=True, slots=True, kw_only=True)
class Product:
    """The product graph plus what the witness extraction needs."""

    graph: Graph = field(compare=False)  # weights
    accepting: BoolArray = field(compare=False)  # per edge of ``graph``: carries the mark
    stutter_accepting: BoolArray = field(compare=False)  # node whose stutter loop accepts
    initial: IntArray = field(compare=False)
    num_automaton_states: int
    num_nodes: int


def edge_midpoints(abstraction: Abstraction) -> FloatArray:
    """(m, 3, 2): midpoint of the edge opposite each vertex of each triangle."""
    corners = abstraction.vertices[abstraction.triangles]
    return np.stack(
        [(corners[:, (i + 1) % 3] + corners[:, (i + 2) % 3]) / 2.0 for i in range(3)], axis=1
    )


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
    """
    m = abstraction.num_triangles
    nq = automaton.num_states
    neighbors = abstraction.neighbors
    closed = convention == "closed"
    letters = list(abstraction.letters)
    table = successor_table(automaton, letters)
    # Letters with the same projection on the automaton's propositions behave the same.
    row_ids: dict[int, int] = {}
    letter_class = np.empty(len(table), dtype=np.int64)
    class_rows: list[list[tuple[tuple[int, int], ...]]] = []

    def class_of(row: list[tuple[tuple[int, int], ...]]) -> int:
        key = id(row)
        if key not in row_ids:
            row_ids[key] = len(class_rows)
            class_rows.append(row)
        return row_ids[key]

    for index, row in enumerate(table):
        letter_class[index] = class_of(row)
    tri_class = letter_class[abstraction.letter_of]
    if starts is None:
        starts = start_cells(abstraction, start_point)
    is_start = np.zeros(m, dtype=bool)
    blocked = np.zeros((m, 3), dtype=bool)
    for cell in starts:
        is_start[cell.triangle] = True
        blocked[cell.triangle, list(cell.blocked)] = True

    # --- moves of D: (t, s) --i--> (n, s') with i != s -------------------------------------
    t = np.repeat(np.arange(m, dtype=np.int64), SLOTS * 3)
    s = np.tile(np.repeat(np.arange(SLOTS, dtype=np.int64), 3), m)
    i = np.tile(np.arange(3, dtype=np.int64), m * SLOTS)
    n = neighbors[t, i]
    valid = (n >= 0) & ((i != s) | bounces)
    valid &= (s != START_SLOT) | is_start[t]
    # The start's own edges: leaving through one at t = 0 never enters the triangle.
    valid &= (s != START_SLOT) | ~blocked[t, i] | bounces
    t, s, i, n = t[valid], s[valid], i[valid], n[valid]
    keep = allowed[t] & allowed[n]
    t, s, i, n = t[keep], s[keep], i[keep], n[keep]
    # The slot of t among n's neighbours (argmax over a 3-wide boolean axis is slow).
    back = neighbors[n]
    slot = np.where(back[:, 0] == t, 0, np.where(back[:, 1] == t, 1, 2)).astype(np.int64)
    if metric == "hops":
        weight = np.ones(len(t))
    else:
        mids = edge_midpoints(abstraction)
        origin = np.where(
            (s == START_SLOT)[:, None],
            np.asarray(start_point, dtype=np.float64)[None, :],
            mids[t, np.minimum(s, 2)],
        )
        step = mids[t, i] - origin
        # sqrt(dx² + dy²) exactly as numpy's norm computes it, without its temporaries.
        weight = np.sqrt(step[:, 0] * step[:, 0] + step[:, 1] * step[:, 1]) + STUTTER_COST
    move_src = t * SLOTS + s
    move_dst = n * SLOTS + slot
    # A move's kind: the class of the entered triangle's letter, and under the closed
    # convention the class of the crossing instant's letter read before it.
    if closed:
        count = len(letters)
        pair = abstraction.letter_of[t] * count + abstraction.letter_of[n]
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
        move_kind = (crossing_class[pair_index.reshape(-1)] + 1) * stride + tri_class[n]
    else:
        move_kind = tri_class[n]

    # --- stutter: (t, s) stays, reading its own label again --------------------------------
    stay_t = np.repeat(np.arange(m, dtype=np.int64), SLOTS)
    stay_s = np.tile(np.arange(SLOTS, dtype=np.int64), m)
    stay_ok = allowed[stay_t] & ((stay_s != START_SLOT) | is_start[stay_t])
    stay_ok &= (stay_s == START_SLOT) | (neighbors[stay_t, np.minimum(stay_s, 2)] >= 0)
    stay_t, stay_s = stay_t[stay_ok], stay_s[stay_ok]
    stay_node = stay_t * SLOTS + stay_s
    stay_class = tri_class[stay_t]

    sources: list[IntArray] = []
    targets: list[IntArray] = []
    weights: list[FloatArray] = []
    accept: list[BoolArray] = []
    stutter_accepting = np.zeros(m * SLOTS * nq, dtype=bool)
    full = (1 << automaton.num_acc) - 1

    def successors_of(kind: int, q: int) -> dict[int, bool]:
        """Automaton successors of ``q`` over a move of ``kind`` (one or two letters).

        Parallel automaton edges would give duplicate pairs: one per successor, accepting if
        any is (every (node, node') pair is then unique: no sort needed).
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

    for kind in np.unique(move_kind).tolist():
        moves = np.flatnonzero(move_kind == kind)
        for q in range(nq):
            for q_next, accepting in successors_of(kind, q).items():
                sources.append(move_src[moves] * nq + q)
                targets.append(move_dst[moves] * nq + q_next)
                weights.append(weight[moves])
                accept.append(np.full(len(moves), accepting))
    for cls in np.unique(stay_class).tolist():
        stays = np.flatnonzero(stay_class == cls)
        for q in range(nq):
            for q_next, accepting in successors_of(cls, q).items():
                if q_next == q:
                    if accepting:
                        stutter_accepting[stay_node[stays] * nq + q] = True
                    continue
                sources.append(stay_node[stays] * nq + q)
                targets.append(stay_node[stays] * nq + q_next)
                weights.append(np.full(len(stays), STUTTER_COST))
                accept.append(np.full(len(stays), accepting))
    size = m * SLOTS * nq
    if sources:
        src = np.concatenate(sources)
        dst = np.concatenate(targets)
        wgt = np.concatenate(weights)
        acc = np.concatenate(accept)
        # The pieces are copied: free them before the graph makes its sorted copies.
        sources.clear()
        targets.clear()
        weights.clear()
        accept.clear()
    else:
        src = dst = np.zeros(0, dtype=np.int64)
        wgt = np.zeros(0)
        acc = np.zeros(0, dtype=bool)
    graph, order = Graph.from_edges(src, dst, wgt, size)
    del src, dst, wgt  # the graph holds its own, sorted copies
    accepting_edges = acc[order]
    # Initial nodes: each start triangle after reading (the start point's letter, under the
    # closed convention, then) its own label.
    first = [automaton.initial]
    if closed:
        point_row = successor_table(automaton, [tuple(sorted({*start_label, POINT}))])[0]
        first = list(dict.fromkeys(q for q, _ in point_row[automaton.initial]))
    initial_nodes: set[int] = set()
    for cell in starts:
        if not allowed[cell.triangle]:
            continue
        row = class_rows[int(tri_class[cell.triangle])]
        for q0 in first:
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
