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

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.sparse import csr_matrix

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.guards import successor_table
from tlmpc.automata.model import Automaton
from tlmpc.planning.boundary import POINT, StartCell, crossing_letter
from tlmpc.planning.model import Witness
from tlmpc.planning.product import SLOTS, START_SLOT, STUTTER_COST, BoolArray, Product

Letter = tuple[str, ...]


@dataclass(frozen=True, slots=True)
class PassageCells:
    """The arrival cells appended to a product: node ``base + c * Q + q`` is cell ``c``."""

    base: int
    triangle: IntArray = field(compare=False)  # (P,) the triangle entered at the vertex
    vertex: IntArray = field(compare=False)  # (P,) the mesh vertex passed through

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


def contact_vertices(abstraction: Abstraction) -> IntArray:
    """Mesh vertices where the triangles around carry at least two different labels, and
    *pinches*: vertices of the mesh's outline whose triangles form two or more fans that
    share no edge (free space touching itself at a point between obstacles)."""
    count = abstraction.vertices.shape[0]
    corner_vertex = abstraction.triangles.reshape(-1)
    corner_letter = np.repeat(abstraction.letter_of, 3)
    low = np.full(count, np.iinfo(np.int64).max, dtype=np.int64)
    high = np.full(count, -1, dtype=np.int64)
    np.minimum.at(low, corner_vertex, corner_letter)
    np.maximum.at(high, corner_vertex, corner_letter)
    found = set(np.flatnonzero((high >= 0) & (low != high)).tolist())
    # Pinches lie on the outline: an endpoint of an edge without a neighbour.
    t, i = np.nonzero(abstraction.neighbors < 0)
    outline = np.unique(
        np.concatenate(
            [abstraction.triangles[t, (i + 1) % 3], abstraction.triangles[t, (i + 2) % 3]]
        )
    )
    candidates = np.setdiff1d(outline, np.fromiter(found, dtype=np.int64, count=len(found)))
    if len(candidates):
        holder = np.isin(abstraction.triangles, candidates)
        around: dict[int, list[int]] = {}
        for tri, local in zip(*np.nonzero(holder), strict=True):
            around.setdefault(int(abstraction.triangles[tri, local]), []).append(int(tri))
        for v, triangles in around.items():
            if _fans(abstraction, triangles) > 1:
                found.add(v)
    return np.asarray(sorted(found), dtype=np.int64)


def _fans(abstraction: Abstraction, triangles: list[int]) -> int:
    """How many edge-connected groups ``triangles`` (all around one vertex) form."""
    members = set(triangles)
    seen: set[int] = set()
    groups = 0
    for first in triangles:
        if first in seen:
            continue
        groups += 1
        stack = [first]
        seen.add(first)
        while stack:
            current = stack.pop()
            for n in abstraction.neighbors[current].tolist():
                if n in members and n not in seen:
                    seen.add(n)
                    stack.append(n)
    return groups


def vertex_point_letters(abstraction: Abstraction) -> dict[int, Letter]:
    """The closed convention's letter at each contact vertex: every region of a triangle
    around it (regions are unions of triangles, so these are exactly the regions whose
    closure holds the vertex), with :data:`POINT`."""
    contacts = contact_vertices(abstraction)
    names: dict[int, set[str]] = {v: set() for v in contacts.tolist()}
    touching = np.flatnonzero(np.isin(abstraction.triangles, contacts).any(axis=1))
    for t in touching.tolist():
        for v in abstraction.triangles[t].tolist():
            if v in names:
                names[v].update(abstraction.labels(t))
    return {v: tuple(sorted({*found, POINT})) for v, found in names.items()}


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
    edge: :func:`passage_turns` names those triangles, which refinement splits.
    """
    nq = automaton.num_states
    m = abstraction.num_triangles
    base = m * SLOTS * nq
    closed = convention == "closed"
    contacts = contact_vertices(abstraction)
    point_letters = vertex_point_letters(abstraction) if closed else {}
    around: dict[int, list[tuple[int, int]]] = {int(v): [] for v in contacts.tolist()}
    touching = np.flatnonzero(np.isin(abstraction.triangles, contacts).any(axis=1) & allowed)
    for t in touching.tolist():
        for k, v in enumerate(abstraction.triangles[t].tolist()):
            if v in around:
                around[v].append((t, k))
    cell_triangle: list[int] = []
    cell_vertex: list[int] = []
    cell_local: list[int] = []
    cell_index: dict[tuple[int, int], int] = {}
    for v, cells in around.items():
        if len(cells) < 2:
            continue
        for t, k in cells:
            cell_index[(t, v)] = len(cell_triangle)
            cell_triangle.append(t)
            cell_vertex.append(v)
            cell_local.append(k)
    cells_info = PassageCells(
        base=base,
        triangle=np.asarray(cell_triangle, dtype=np.int64),
        vertex=np.asarray(cell_vertex, dtype=np.int64),
    )
    if not cell_triangle:
        return product, cells_info

    letters: list[Letter] = []
    letter_ids: dict[Letter, int] = {}

    def letter_id(letter: Letter) -> int:
        if letter not in letter_ids:
            letter_ids[letter] = len(letters)
            letters.append(letter)
        return letter_ids[letter]

    full = (1 << automaton.num_acc) - 1
    vertices = abstraction.vertices
    corners_of = abstraction.triangles
    start_blocked = {cell.triangle: set(cell.blocked) for cell in starts}
    start = np.asarray(start_point, dtype=np.float64)

    def midpoint(t: int, edge: int) -> FloatArray:
        a = vertices[corners_of[t, (edge + 1) % 3]]
        b = vertices[corners_of[t, (edge + 2) % 3]]
        middle: FloatArray = (a + b) / 2.0
        return middle

    # Moves as (source node without q, target node without q, letters read, weight).
    moves: list[tuple[int, int, tuple[int, ...], float]] = []
    stays: list[tuple[int, int]] = []  # (arrival node without q, letter of its triangle)
    for c, (t2, v, k2) in enumerate(zip(cell_triangle, cell_vertex, cell_local, strict=True)):
        arrival = base + c * nq
        point = vertices[v]
        own = letter_id(abstraction.labels(t2))
        reads_at_vertex = (letter_id(point_letters[v]), own) if closed else (own,)
        # Into the cell: from every other triangle around v, entered opposite v or started
        # off both of its edges through v.
        for t1, k1 in around[v]:
            if t1 == t2 and not bounces:
                continue  # back into the same triangle: a U-turn at v (refinement splits it)
            entries = (k1, (k1 + 1) % 3, (k1 + 2) % 3) if bounces else (k1,)
            sources = [
                (t1 * SLOTS + e, float(np.linalg.norm(point - midpoint(t1, e))))
                for e in entries
                if abstraction.neighbors[t1, e] >= 0
            ]
            if t1 in start_blocked:
                through_v = {(k1 + 1) % 3, (k1 + 2) % 3}
                # A start on an edge through v would slide along it (even while searching
                # with bounces: refinement does not see the start's edges).
                if not (through_v & start_blocked[t1]):
                    sources.append((t1 * SLOTS + START_SLOT, float(np.linalg.norm(point - start))))
            for source, length in sources:
                weight = 1.0 if metric == "hops" else length + STUTTER_COST
                moves.append((source, arrival, reads_at_vertex, weight))
        # Out of the cell: through the edge opposite v only (any edge, with bounces).
        for exit_edge in (k2, (k2 + 1) % 3, (k2 + 2) % 3) if bounces else (k2,):
            n = int(abstraction.neighbors[t2, exit_edge])
            if n < 0 or not allowed[n]:
                continue
            slot = int(np.flatnonzero(abstraction.neighbors[n] == t2)[0])
            entered = letter_id(abstraction.labels(n))
            crossing = crossing_letter(abstraction.labels(t2), abstraction.labels(n))
            reads = (letter_id(crossing), entered) if closed else (entered,)
            length = float(np.linalg.norm(midpoint(t2, exit_edge) - point))
            weight = 1.0 if metric == "hops" else length + STUTTER_COST
            moves.append((arrival, n * SLOTS + slot, reads, weight))
        stays.append((arrival, own))

    table = successor_table(automaton, letters)

    def read(q: int, word: tuple[int, ...]) -> dict[int, bool]:
        frontier: dict[int, int] = {q: 0}
        for letter in word:
            following: dict[int, int] = {}
            for state, mask in frontier.items():
                for q_next, mark in table[letter][state]:
                    following[q_next] = following.get(q_next, 0) | mask | mark
            frontier = following
        return {state: mask == full for state, mask in frontier.items()}

    src: list[int] = []
    dst: list[int] = []
    wgt: list[float] = []
    acc: list[bool] = []
    for source, target, word, weight in moves:
        for q in range(nq):
            for q_next, accepting in read(q, word).items():
                src.append(source * nq + q if source < base else source + q)
                dst.append(target * nq + q_next if target < base else target + q_next)
                wgt.append(weight)
                acc.append(accepting)
    size = base + len(cell_triangle) * nq
    stutter = np.zeros(size, dtype=bool)
    stutter[: product.num_nodes] = product.stutter_accepting
    for arrival, own in stays:
        for q in range(nq):
            for q_next, accepting in read(q, (own,)).items():
                if q_next == q:
                    stutter[arrival + q] |= accepting
                    continue
                src.append(arrival + q)
                dst.append(arrival + q_next)
                wgt.append(STUTTER_COST)
                acc.append(accepting)
    old = product.graph.tocoo()
    old_acc = product.accepting.tocoo()
    all_sources = np.concatenate([old.row.astype(np.int64), np.asarray(src, dtype=np.int64)])
    targets = np.concatenate([old.col.astype(np.int64), np.asarray(dst, dtype=np.int64)])
    weights = np.concatenate([old.data, np.asarray(wgt, dtype=np.float64)])
    marked = np.asarray(acc, dtype=bool)
    graph = csr_matrix((weights, (all_sources, targets)), shape=(size, size))
    graph.sum_duplicates()
    graph.sort_indices()
    new_src = np.asarray(src, dtype=np.int64)[marked]
    new_dst = np.asarray(dst, dtype=np.int64)[marked]
    accepting = csr_matrix(
        (
            np.ones(len(old_acc.row) + len(new_src)),
            (
                np.concatenate([old_acc.row.astype(np.int64), new_src]),
                np.concatenate([old_acc.col.astype(np.int64), new_dst]),
            ),
        ),
        shape=(size, size),
    )
    accepting.data[:] = 1.0
    accepting.sum_duplicates()
    accepting.data[:] = 1.0
    accepting.sort_indices()
    extended = replace(
        product, graph=graph, accepting=accepting, stutter_accepting=stutter, num_nodes=size
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
