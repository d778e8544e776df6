"""The product of the transition system D (with stutter self-loops) and an automaton.

Built with numpy as a sparse graph, never one Python object per state.  A product node is
``((t * 4 + s) * Q + q)``: triangle ``t``, *entry slot* ``s`` (the edge of ``t`` the robot came
in through, ``3`` at the start), automaton state ``q``.  A move may leave ``t`` through any
edge but its entry edge, which is how no plan ever bounces: an affine field cannot enter a
triangle and leave it through the same edge.  Stuttering (staying in ``t``) keeps the slot.

The automaton reads the label of the triangle being entered (and of the start triangle first).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from scipy.sparse import csr_matrix

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.guards import successor_table
from tlmpc.automata.model import Automaton

SLOTS = 4  # three edges, and "no entry edge yet" for the start
START_SLOT = 3
#: Weight of a stutter step: Dijkstra on scipy ignores zero weights, and stutter is free.
STUTTER_COST = 1e-9

BoolArray = npt.NDArray[np.bool_]


@dataclass(frozen=True, slots=True, kw_only=True)
class Product:
    """The product graph as CSR plus what the witness extraction needs."""

    graph: csr_matrix = field(compare=False)  # weights
    accepting: csr_matrix = field(compare=False)  # 1 where the edge carries the mark
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
    bounces: bool = False,
) -> Product:
    """The product graph restricted to ``allowed`` triangles.

    ``metric`` is ``"length"`` (Euclidean length through the crossed edges' midpoints,
    starting at ``start_point``) or ``"hops"`` (one per move).  ``bounces=True`` also allows
    leaving a triangle through its entry edge: that graph is stutter-equivalent to the face
    graph of the region arrangement, so it decides whether *any* continuous trajectory
    satisfies the task (see docs/planning.md); its bounces are realised by refinement.
    """
    m = abstraction.num_triangles
    nq = automaton.num_states
    neighbors = abstraction.neighbors
    table = successor_table(automaton, abstraction.letters)
    # Letters with the same projection on the automaton's propositions behave the same.
    row_ids: dict[int, int] = {}
    letter_class = np.empty(len(table), dtype=np.int64)
    class_rows: list[list[tuple[tuple[int, int], ...]]] = []
    for index, row in enumerate(table):
        key = id(row)
        if key not in row_ids:
            row_ids[key] = len(class_rows)
            class_rows.append(row)
        letter_class[index] = row_ids[key]
    tri_class = letter_class[abstraction.letter_of]

    # --- moves of D: (t, s) --i--> (n, s') with i != s -------------------------------------
    t = np.repeat(np.arange(m, dtype=np.int64), SLOTS * 3)
    s = np.tile(np.repeat(np.arange(SLOTS, dtype=np.int64), 3), m)
    i = np.tile(np.arange(3, dtype=np.int64), m * SLOTS)
    n = neighbors[t, i]
    valid = (n >= 0) & ((i != s) | bounces)
    valid &= (s != START_SLOT) | (t == abstraction.start)
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
        weight = np.linalg.norm(mids[t, i] - origin, axis=1) + STUTTER_COST
    move_src = t * SLOTS + s
    move_dst = n * SLOTS + slot
    move_class = tri_class[n]

    # --- stutter: (t, s) stays, reading its own label again --------------------------------
    stay_t = np.repeat(np.arange(m, dtype=np.int64), SLOTS)
    stay_s = np.tile(np.arange(SLOTS, dtype=np.int64), m)
    stay_ok = allowed[stay_t] & ((stay_s != START_SLOT) | (stay_t == abstraction.start))
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

    for cls, rows in enumerate(class_rows):
        moves = np.flatnonzero(move_class == cls)
        stays = np.flatnonzero(stay_class == cls)
        for q in range(nq):
            # Parallel automaton edges would give duplicate pairs: keep one per successor,
            # accepting if any is (every (node, node') pair is then unique: no sort needed).
            successors: dict[int, bool] = {}
            for q_next, mask in rows[q]:
                successors[q_next] = successors.get(q_next, False) or mask == full
            for q_next, accepting in successors.items():
                if len(moves):
                    sources.append(move_src[moves] * nq + q)
                    targets.append(move_dst[moves] * nq + q_next)
                    weights.append(weight[moves])
                    accept.append(np.full(len(moves), accepting))
                if len(stays):
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
    else:
        src = dst = np.zeros(0, dtype=np.int64)
        wgt = np.zeros(0)
        acc = np.zeros(0, dtype=bool)
    graph = csr_matrix((wgt, (src, dst)), shape=(size, size))
    graph.sort_indices()  # canonical order: the searches break ties as they always did
    accepting_graph = csr_matrix(
        (np.ones(int(acc.sum())), (src[acc], dst[acc])), shape=(size, size)
    )
    accepting_graph.sort_indices()
    start_row = class_rows[int(tri_class[abstraction.start])]
    initial = np.array(
        sorted(
            {
                (abstraction.start * SLOTS + START_SLOT) * nq + q
                for q, _ in start_row[automaton.initial]
            }
        ),
        dtype=np.int64,
    )
    if not allowed[abstraction.start]:
        initial = np.zeros(0, dtype=np.int64)
    return Product(
        graph=graph,
        accepting=accepting_graph,
        stutter_accepting=stutter_accepting,
        initial=initial,
        num_automaton_states=nq,
        num_nodes=size,
    )
