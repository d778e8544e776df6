"""Vertex passages: plans through a single point where regions touch only at a corner.

No sequence of edge crossings passes through a mesh vertex, so two faces of the region
arrangement that touch only at a point are not connected in the triangle graph.  A *vertex
passage* connects them: in a triangle ``T`` with vertex ``v``, the pursuit law
``u(x) = s (v - x) / |v - x|`` drives every point of ``T`` along a straight segment to ``v``
(``T`` is convex) and reaches it in time ``|v - x| / s``; from ``v`` the robot goes on in any
other triangle ``T'`` around ``v`` with that triangle's ordinary field, like a start on a
mesh vertex (it may leave ``T'`` only through the edge opposite ``v``, or stay in it).

The robot must enter ``T`` through the edge opposite ``v`` (entering through an edge that
holds ``v`` and running to ``v`` would slide along that edge, never inside ``T``), or start in
``T`` off both edges through ``v``.  At the instant it is at ``v`` it reads, under the closed
convention, every region whose closure holds ``v`` (with the point marker); under the
right-continuous convention the label of ``T'``.

The product gains one *arrival cell* per (triangle ``T'``, vertex ``v`` of it): the robot is at
``v`` having entered ``T'``.  Its nodes come after the ordinary product's nodes; moves into
them are passages, moves out of them leave ``T'`` through the edge opposite ``v``.  Only
vertices where the labels of the triangles around differ get passages: around any other
vertex every triangle lies in one face, and a passage would add no run the edge moves lack.
Plans use passages only when no plan exists without them (see
:func:`tlmpc.planning.complete.plan_complete`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.guards import successor_table
from tlmpc.automata.model import Automaton
from tlmpc.base.content import ContentEquality
from tlmpc.planning.boundary import StartCell, crossing_letter
from tlmpc.planning.contacts import contact_vertices, vertex_point_letters
from tlmpc.planning.model import Witness
from tlmpc.planning.product import SLOTS, START_SLOT, STUTTER_COST, BoolArray, Product
from tlmpc.planning.search import Graph

Letter = tuple[str, ...]


@dataclass(frozen=True, slots=True, eq=False)
class PassageCells(ContentEquality):
    """The arrival cells appended to a product: node ``base + c * Q + q`` is cell ``c``."""

    base: int
    triangle: IntArray  # (P,) the triangle entered at the vertex
    vertex: IntArray  # (P,) the mesh vertex passed through

    def triangle_of(self, node: int, num_states: int) -> int:
        """The triangle of any product node (ordinary or arrival)."""
        if node >= self.base:
            return int(self.triangle[(node - self.base) // num_states])
        return (node // num_states) // SLOTS

    def vertex_of(self, node: int, num_states: int) -> int | None:
        """The vertex passed through to reach ``node`` (None for an ordinary node)."""
        if node >= self.base:
            return int(self.vertex[(node - self.base) // num_states])
        return None


def add_vertex_passages(
    product: Product,
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    allowed: BoolArray,
    starts: tuple[StartCell, ...],
    start_point: tuple[float, float],
    metric: str,
    convention: str,
    bounces: bool = False,
) -> tuple[Product, PassageCells]:
    """``product`` with vertex passages (see the module doc) and its arrival cells.

    With ``bounces`` (the search for U-turns), a passage may also start from a triangle
    entered through an edge that holds the vertex, and an arrival may leave through such an
    edge: :func:`passage_turns` names those triangles, which refinement splits.  Built with
    numpy over all corners at once, as the product is.
    """
    nq = automaton.num_states
    m = abstraction.num_triangles
    base = m * SLOTS * nq
    closed = convention == "closed"
    triangles = abstraction.triangles
    vertices = abstraction.vertices
    neighbors = abstraction.neighbors
    contacts = contact_vertices(abstraction)
    # Cells: the corners (t, k) of allowed triangles at contact vertices, grouped by vertex.
    at_contact = np.isin(triangles, contacts) & allowed[:, None]
    cell_t, cell_k = np.nonzero(at_contact)
    cell_v = triangles[cell_t, cell_k]
    order = np.argsort(cell_v, kind="stable")
    cell_t, cell_k, cell_v = cell_t[order], cell_k[order], cell_v[order]
    _, group_start, group_size = np.unique(cell_v, return_index=True, return_counts=True)
    keep = np.repeat(group_size >= 2, group_size)
    cell_t, cell_k, cell_v = cell_t[keep], cell_k[keep], cell_v[keep]
    _, group_start, group_size = np.unique(cell_v, return_index=True, return_counts=True)
    cells_info = PassageCells(base=base, triangle=cell_t.astype(np.int64), vertex=cell_v)
    count = len(cell_t)
    if count == 0:
        return product, cells_info
    arrival_off = base + np.arange(count, dtype=np.int64) * nq

    def midpoints(t: IntArray, edge: IntArray) -> FloatArray:
        a = vertices[triangles[t, (edge + 1) % 3]]
        b = vertices[triangles[t, (edge + 2) % 3]]
        middle: FloatArray = (a + b) / 2.0
        return middle

    def weights(lengths: FloatArray) -> FloatArray:
        if metric == "hops":
            return np.ones(len(lengths))
        result: FloatArray = lengths + STUTTER_COST
        return result

    # Letters read, as ids into a local table: the triangles' letters first.
    letters: list[Letter] = list(abstraction.letters)
    letter_ids: dict[Letter, int] = {letter: i for i, letter in enumerate(letters)}

    def letter_id(letter: Letter) -> int:
        if letter not in letter_ids:
            letter_ids[letter] = len(letters)
            letters.append(letter)
        return letter_ids[letter]

    # --- into a cell: every pair (source corner, target cell) around one vertex -----------
    per_cell_group = np.repeat(np.arange(len(group_size)), group_size)
    sizes = group_size[per_cell_group]
    source = np.repeat(np.arange(count), sizes)  # source corner index
    within = np.arange(len(source)) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    target = group_start[per_cell_group][source] + within  # target cell index
    if not bounces:
        distinct = cell_t[source] != cell_t[target]
        source, target = source[distinct], target[distinct]
    src_t, src_k = cell_t[source], cell_k[source]
    entries = [src_k, (src_k + 1) % 3, (src_k + 2) % 3] if bounces else [src_k]
    move_src: list[IntArray] = []
    move_dst: list[IntArray] = []
    move_len: list[FloatArray] = []
    move_first: list[IntArray] = []  # the letter read first (-1: none)
    move_second: list[IntArray] = []
    corner_point = vertices[cell_v[source]]
    if closed:
        point_ids = {
            v: letter_id(letter) for v, letter in vertex_point_letters(abstraction).items()
        }
        at_vertex = np.array([point_ids[v] for v in cell_v.tolist()], dtype=np.int64)
    else:
        at_vertex = np.full(count, -1, dtype=np.int64)
    entered_letter = abstraction.letter_of[cell_t[target]]
    for entry in entries:
        valid = neighbors[src_t, entry] >= 0
        move_src.append((src_t[valid] * SLOTS + entry[valid]) * nq)
        move_dst.append(arrival_off[target[valid]])
        move_len.append(
            np.linalg.norm(corner_point[valid] - midpoints(src_t[valid], entry[valid]), axis=1)
        )
        move_first.append(at_vertex[target[valid]])
        move_second.append(entered_letter[valid])
    # From the start, off both edges of its triangle through the vertex (a start on such an
    # edge would slide along it, even while searching with bounces: refinement does not see
    # the start's edges).
    start_ok = np.zeros(len(source), dtype=bool)
    for cell in starts:
        blocked = np.zeros(3, dtype=bool)
        blocked[list(cell.blocked)] = True
        mine = src_t == cell.triangle
        through_blocked = blocked[(src_k + 1) % 3] | blocked[(src_k + 2) % 3]
        start_ok |= mine & ~through_blocked
    start_xy = np.asarray(start_point, dtype=np.float64)
    move_src.append((src_t[start_ok] * SLOTS + START_SLOT) * nq)
    move_dst.append(arrival_off[target[start_ok]])
    move_len.append(np.linalg.norm(corner_point[start_ok] - start_xy[None, :], axis=1))
    move_first.append(at_vertex[target[start_ok]])
    move_second.append(entered_letter[start_ok])

    # --- out of a cell: through the edge opposite the vertex (any edge, with bounces) -----
    cells = np.arange(count)
    exits = [cell_k, (cell_k + 1) % 3, (cell_k + 2) % 3] if bounces else [cell_k]
    for exit_edge in exits:
        n = neighbors[cell_t, exit_edge]
        valid = n >= 0
        valid[valid] &= allowed[n[valid]]
        t2, e2, n2 = cell_t[valid], exit_edge[valid], n[valid]
        back = neighbors[n2]
        slot = np.where(back[:, 0] == t2, 0, np.where(back[:, 1] == t2, 1, 2)).astype(np.int64)
        move_src.append(arrival_off[cells[valid]])
        move_dst.append((n2 * SLOTS + slot) * nq)
        move_len.append(np.linalg.norm(midpoints(t2, e2) - vertices[cell_v[valid]], axis=1))
        if closed:
            stride = len(abstraction.letters)
            pairs = abstraction.letter_of[t2] * stride + abstraction.letter_of[n2]
            unique_pairs, inverse = np.unique(pairs, return_inverse=True)
            crossing = np.array(
                [
                    letter_id(crossing_letter(letters[key // stride], letters[key % stride]))
                    for key in unique_pairs.tolist()
                ],
                dtype=np.int64,
            )
            move_first.append(crossing[inverse.reshape(-1)])
        else:
            move_first.append(np.full(len(t2), -1, dtype=np.int64))
        move_second.append(abstraction.letter_of[n2])

    src_off = np.concatenate(move_src)
    dst_off = np.concatenate(move_dst)
    weight = weights(np.concatenate(move_len))
    first = np.concatenate(move_first)
    second = np.concatenate(move_second)

    table = successor_table(automaton, letters)
    full = (1 << automaton.num_acc) - 1
    # Letters with one projection on the automaton's propositions share one row (the table
    # caches it): moves are grouped by those classes, not by letters (maps have many).
    rows: list[list[tuple[tuple[int, int], ...]]] = []
    row_index: dict[int, int] = {}
    letter_class = np.empty(len(letters), dtype=np.int64)
    for index, row in enumerate(table):
        letter_class[index] = row_index.setdefault(id(row), len(rows))
        if letter_class[index] == len(rows):
            rows.append(row)

    def read(q: int, word: tuple[int, ...]) -> dict[int, bool]:
        frontier: dict[int, int] = {q: 0}
        for cls in word:
            following: dict[int, int] = {}
            for state, mask in frontier.items():
                for q_next, mark in rows[cls][state]:
                    following[q_next] = following.get(q_next, 0) | mask | mark
            frontier = following
        return {state: mask == full for state, mask in frontier.items()}

    sources: list[IntArray] = []
    targets: list[IntArray] = []
    costs: list[FloatArray] = []
    marks: list[BoolArray] = []
    classes = len(rows) + 1
    first_class = np.where(first >= 0, letter_class[np.maximum(first, 0)], -1)
    key = (first_class + 1) * classes + letter_class[second]
    kinds, kind_of = np.unique(key, return_inverse=True)
    kind_of = kind_of.reshape(-1)
    for index, kind in enumerate(kinds.tolist()):
        moves = np.flatnonzero(kind_of == index)
        x, y = kind // classes - 1, kind % classes
        word = (x, y) if x >= 0 else (y,)
        for q in range(nq):
            for q_next, accepting in read(q, word).items():
                sources.append(src_off[moves] + q)
                targets.append(dst_off[moves] + q_next)
                costs.append(weight[moves])
                marks.append(np.full(len(moves), accepting))
    # Stutter in a cell: reading its triangle's letter again.
    size = base + count * nq
    stutter = np.zeros(size, dtype=bool)
    stutter[: product.num_nodes] = product.stutter_accepting
    own = letter_class[abstraction.letter_of[cell_t]]
    for cls in np.unique(own).tolist():
        stays = np.flatnonzero(own == cls)
        for q in range(nq):
            for q_next, accepting in read(q, (cls,)).items():
                if q_next == q:
                    if accepting:
                        stutter[arrival_off[stays] + q] = True
                    continue
                sources.append(arrival_off[stays] + q)
                targets.append(arrival_off[stays] + q_next)
                costs.append(np.full(len(stays), STUTTER_COST))
                marks.append(np.full(len(stays), accepting))

    old = product.graph
    new_src = np.concatenate(sources) if sources else np.zeros(0, dtype=np.int64)
    new_dst = np.concatenate(targets) if targets else np.zeros(0, dtype=np.int64)
    new_cost = np.concatenate(costs) if costs else np.zeros(0)
    new_mark = np.concatenate(marks) if marks else np.zeros(0, dtype=bool)
    # Stable by source: every node's ordinary edges keep their order, passages come after.
    graph, order = Graph.from_edges(
        np.concatenate([old.sources, new_src]),
        np.concatenate([old.targets, new_dst]),
        np.concatenate([old.weights, new_cost]),
        size,
    )
    accepting_edges = np.concatenate([product.accepting, new_mark])[order]
    extended = replace(
        product, graph=graph, accepting=accepting_edges, stutter_accepting=stutter, num_nodes=size
    )
    return extended, cells_info


def passage_turns(abstraction: Abstraction, witness: Witness) -> list[int]:
    """Triangles where a vertex passage needs a turn the fields cannot make: entered through
    an edge that holds the passage's vertex before running to it (the run would slide along
    that edge), or left through such an edge right after arriving at it.  Splitting them into
    fans (as for U-turns) gives the room to turn."""
    path = [*witness.prefix, *witness.cycle]
    loop = None if witness.is_stay else len(witness.prefix)

    def following(i: int) -> int | None:
        return i + 1 if i + 1 < len(path) else loop

    def previous(i: int) -> list[int]:
        found = [i - 1] if i > 0 else []
        if loop is not None and i == loop:
            found.append(len(path) - 1)
        return found

    turns: set[int] = set()
    for i, vertex in witness.passages:
        here = path[i]
        back = following(i)
        if back is not None and path[back] == here:
            turns.add(here)  # to the vertex and back into the same triangle
        for j in previous(i):
            if vertex in abstraction.triangles[path[j]]:
                turns.add(here)
        arrival = following(i)
        if arrival is None:
            continue
        after = following(arrival)
        if after is not None and after != arrival and vertex in abstraction.triangles[path[after]]:
            turns.add(path[arrival])
    return sorted(turns)
