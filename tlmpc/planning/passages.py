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

A vertex with ``g`` triangles around it gives about ``g**2`` passages: their product edges are
bounded from the corners' counts alone (:func:`estimate_passage_edges`) and charged against
the planner's budget (:func:`tlmpc.planning.budget.check_passage_edges`, P060) before any
passage is listed.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.automata.guards import successor_table
from tlmpc.automata.model import Automaton
from tlmpc.base.content import ContentEquality
from tlmpc.planning import budget
from tlmpc.planning.boundary import StartCell, crossing_letter
from tlmpc.planning.contacts import contact_vertices, vertex_point_letters
from tlmpc.planning.model import Witness
from tlmpc.planning.product import SLOTS, START_SLOT, STUTTER_COST, BoolArray, Product
from tlmpc.planning.search import Graph
from tlmpc.planning.timing import MoveTimes

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
    times: MoveTimes | None = None,
) -> tuple[Product, PassageCells]:
    """``product`` with vertex passages (see the module doc) and its arrival cells.

    With ``bounces`` (the search for U-turns), a passage may also start from a triangle
    entered through an edge that holds the vertex, and an arrival may leave through such an
    edge: :func:`passage_turns` names those triangles, which refinement splits.  Built with
    numpy over all corners at once, as the product is.

    Raises :class:`~tlmpc.base.errors.UsageError` (P060) before listing any passage when
    :func:`estimate_passage_edges` exceeds the planner's budget.
    """
    nq = automaton.num_states
    base = abstraction.num_triangles * SLOTS * nq
    corners = _ArrivalCorners.around_contacts(abstraction, allowed)
    corners.charge(
        abstraction,
        automaton,
        allowed=allowed,
        starts=starts,
        bounces=bounces,
        closed=convention == "closed",
    )
    cells_info = PassageCells(
        base=base, triangle=corners.triangle.astype(np.int64), vertex=corners.vertex
    )
    count = len(corners.triangle)
    if count == 0:
        return product, cells_info
    arrival = base + np.arange(count, dtype=np.int64) * nq  # each cell's first node
    letters = _LetterIds(list(abstraction.letters))
    moves = _PassageMoves()
    point_letter = (
        _vertex_point_letter_ids(abstraction, corners, letters)
        if convention == "closed"
        else np.full(count, -1, dtype=np.int64)
    )
    source, target = corners.pairs(bounces=bounces)
    _add_arrivals_from_entries(
        moves, abstraction, corners, source, target, arrival, point_letter, nq, bounces=bounces
    )
    _add_arrivals_from_start(
        moves, abstraction, corners, source, target, arrival, point_letter, starts, start_point, nq
    )
    _add_departures(
        moves,
        abstraction,
        corners,
        arrival,
        letters,
        allowed,
        nq,
        bounces=bounces,
        closed=convention == "closed",
    )
    reader = _WordReader(automaton, letters.letters)
    edges = _passage_edges(moves, reader, metric, nq, times)
    size = base + count * nq
    stutter = np.zeros(size, dtype=bool)
    stutter[: product.num_nodes] = product.stutter_accepting
    own = reader.letter_class[abstraction.letter_of[corners.triangle]]
    edges += _arrival_stutter_edges(own, arrival, reader, stutter, nq)
    return _with_edges(product, edges, stutter, size), cells_info


@dataclass(frozen=True, slots=True)
class _ArrivalCorners:
    """The corners ``(t, k)`` of allowed triangles at contact vertices (``v`` is corner
    ``k`` of ``t``), grouped by vertex; only vertices with two corners or more."""

    triangle: IntArray
    corner: IntArray
    vertex: IntArray
    group_start: IntArray  # per vertex, in increasing order: its first corner
    group_size: IntArray

    @staticmethod
    def around_contacts(abstraction: Abstraction, allowed: BoolArray) -> _ArrivalCorners:
        """The corners of ``allowed`` triangles at :func:`contact_vertices`."""
        triangles = abstraction.triangles
        at_contact = np.isin(triangles, contact_vertices(abstraction)) & allowed[:, None]
        cell_t, cell_k = np.nonzero(at_contact)
        cell_v = triangles[cell_t, cell_k]
        order = np.argsort(cell_v, kind="stable")
        cell_t, cell_k, cell_v = cell_t[order], cell_k[order], cell_v[order]
        _, group_start, group_size = np.unique(cell_v, return_index=True, return_counts=True)
        keep = np.repeat(group_size >= 2, group_size)
        cell_t, cell_k, cell_v = cell_t[keep], cell_k[keep], cell_v[keep]
        _, group_start, group_size = np.unique(cell_v, return_index=True, return_counts=True)
        return _ArrivalCorners(
            triangle=cell_t,
            corner=cell_k,
            vertex=cell_v,
            group_start=group_start,
            group_size=group_size,
        )

    def move_count(
        self,
        abstraction: Abstraction,
        *,
        allowed: BoolArray,
        starts: tuple[StartCell, ...],
        bounces: bool,
    ) -> int:
        """How many passage moves into and out of these corners' arrival cells
        :func:`add_vertex_passages` makes, from the group sizes and each corner's edges
        (a start on an edge through the vertex counted as if it were off it)."""
        # Each triangle holds a vertex once: a corner in a group of g is the source of g
        # passages, one of them back into its own triangle (a U-turn, only with bounces).
        targets = np.repeat(self.group_size.astype(np.int64), self.group_size)
        if not bounces:
            targets -= 1
        # The edge opposite the vertex; with bounces the two through it as well.
        turns = (0, 1, 2) if bounces else (0,)
        sides = self.corner[:, None] + np.asarray(turns)[None, :]
        across = abstraction.neighbors[self.triangle[:, None], sides % 3]
        entered = (across >= 0).sum(axis=1)
        left = ((across >= 0) & allowed[np.maximum(across, 0)]).sum(axis=1)
        start_triangles = np.unique([cell.triangle for cell in starts])
        from_start = np.isin(self.triangle, start_triangles)
        return int((entered * targets).sum() + targets[from_start].sum() + left.sum())

    def edge_bound(
        self,
        abstraction: Abstraction,
        automaton: Automaton,
        *,
        allowed: BoolArray,
        starts: tuple[StartCell, ...],
        bounces: bool,
        closed: bool,
    ) -> int:
        """An upper bound on the product edges of these corners' passages (see
        :func:`estimate_passage_edges`)."""
        moves = self.move_count(abstraction, allowed=allowed, starts=starts, bounces=bounces)
        one_letter, two_letters = _successor_bounds(automaton)
        word = two_letters if closed else one_letter
        return moves * word + len(self.triangle) * one_letter  # and the cells' stutter steps

    def charge(
        self,
        abstraction: Abstraction,
        automaton: Automaton,
        *,
        allowed: BoolArray,
        starts: tuple[StartCell, ...],
        bounces: bool,
        closed: bool,
    ) -> None:
        """Raises P060 when :meth:`edge_bound` is beyond the planner's budget."""
        if len(self.group_size) == 0:
            return
        widest = int(np.argmax(self.group_size))
        x, y = abstraction.vertices[self.vertex[self.group_start[widest]]].tolist()
        budget.check_passage_edges(
            self.edge_bound(
                abstraction,
                automaton,
                allowed=allowed,
                starts=starts,
                bounces=bounces,
                closed=closed,
            ),
            widest_fan=int(self.group_size[widest]),
            at=(float(x), float(y)),
        )

    def pairs(self, *, bounces: bool) -> tuple[IntArray, IntArray]:
        """Every (source corner, target cell) around one vertex; the same triangle on both
        sides only with ``bounces`` (a U-turn at the vertex)."""
        count = len(self.triangle)
        per_cell_group = np.repeat(np.arange(len(self.group_size)), self.group_size)
        sizes = self.group_size[per_cell_group]
        source = np.repeat(np.arange(count), sizes)
        within = np.arange(len(source)) - np.repeat(np.cumsum(sizes) - sizes, sizes)
        target = self.group_start[per_cell_group][source] + within
        if not bounces:
            distinct = self.triangle[source] != self.triangle[target]
            source, target = source[distinct], target[distinct]
        return source, target


def _successor_bounds(automaton: Automaton) -> tuple[int, int]:
    """Upper bounds, summed over the automaton's states, on the successor states after a word
    of one letter and of two letters: a letter enables at most a state's out-edges, and no
    state has more than ``num_states`` successors."""
    states = automaton.num_states
    out_degree = np.bincount(
        np.fromiter((edge.src for edge in automaton.edges), dtype=np.int64),
        minlength=states,
    )
    then = sum(int(out_degree[edge.dst]) for edge in automaton.edges)
    return min(len(automaton.edges), states * states), min(then, states * states)


def estimate_passage_edges(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    allowed: BoolArray,
    starts: tuple[StartCell, ...],
    convention: str,
    bounces: bool = False,
) -> int:
    """An upper bound on the edges :func:`add_vertex_passages` adds to the product (same
    arguments), from the allowed triangles around each contact vertex and their neighbours
    alone (no passage is listed).

    Per passage source: the edges it may be entered by (the one opposite the vertex, any of
    its three with ``bounces``) times the cells around its vertex (its own only with
    ``bounces``), and as many again from a start triangle; per cell, its exits into allowed
    triangles and its stutter steps.  Each move gives at most as many edges as the automaton
    has successors over the word it reads (two letters under the closed convention).
    """
    return _ArrivalCorners.around_contacts(abstraction, allowed).edge_bound(
        abstraction,
        automaton,
        allowed=allowed,
        starts=starts,
        bounces=bounces,
        closed=convention == "closed",
    )


class _LetterIds:
    """Letters read, as ids into a local table: the triangles' letters first, then the
    vertices' and crossings' letters as they are met."""

    def __init__(self, letters: list[Letter]) -> None:
        self.letters = letters
        self.ids: dict[Letter, int] = {letter: i for i, letter in enumerate(letters)}

    def id_of(self, letter: Letter) -> int:
        """The id of ``letter``, appended to the table if new."""
        if letter not in self.ids:
            self.ids[letter] = len(self.letters)
            self.letters.append(letter)
        return self.ids[letter]


@dataclass(slots=True)
class _PassageMoves:
    """Moves into and out of arrival cells: source and target node offsets (automaton state
    0), length, and the letters read (``first`` is -1 when only ``second`` is read)."""

    source: list[IntArray] = field(default_factory=list)
    target: list[IntArray] = field(default_factory=list)
    length: list[FloatArray] = field(default_factory=list)
    first: list[IntArray] = field(default_factory=list)
    second: list[IntArray] = field(default_factory=list)

    def add(
        self,
        source: IntArray,
        target: IntArray,
        length: FloatArray,
        first: IntArray,
        second: IntArray,
    ) -> None:
        """Append a batch of moves."""
        self.source.append(source)
        self.target.append(target)
        self.length.append(length)
        self.first.append(first)
        self.second.append(second)


def _edge_midpoints(abstraction: Abstraction, t: IntArray, edge: IntArray) -> FloatArray:
    """The midpoint of edge ``edge`` (opposite that corner) of each triangle ``t``."""
    vertices, triangles = abstraction.vertices, abstraction.triangles
    a = vertices[triangles[t, (edge + 1) % 3]]
    b = vertices[triangles[t, (edge + 2) % 3]]
    middle: FloatArray = (a + b) / 2.0
    return middle


def _vertex_point_letter_ids(
    abstraction: Abstraction, corners: _ArrivalCorners, letters: _LetterIds
) -> IntArray:
    """Per cell, the id of its vertex's point letter (read at the instant the robot is
    there, under the closed convention)."""
    point_ids = {
        v: letters.id_of(letter) for v, letter in vertex_point_letters(abstraction).items()
    }
    return np.array([point_ids[v] for v in corners.vertex.tolist()], dtype=np.int64)


def _add_arrivals_from_entries(
    moves: _PassageMoves,
    abstraction: Abstraction,
    corners: _ArrivalCorners,
    source: IntArray,
    target: IntArray,
    arrival: IntArray,
    point_letter: IntArray,
    nq: int,
    *,
    bounces: bool,
) -> None:
    """Passages from a triangle entered through the edge opposite the vertex (any entry
    edge, with ``bounces``) to the vertex, into the target cell."""
    src_t, src_k = corners.triangle[source], corners.corner[source]
    corner_point = abstraction.vertices[corners.vertex[source]]
    entered_letter = abstraction.letter_of[corners.triangle[target]]
    entries = [src_k, (src_k + 1) % 3, (src_k + 2) % 3] if bounces else [src_k]
    for entry in entries:
        valid = abstraction.neighbors[src_t, entry] >= 0
        moves.add(
            (src_t[valid] * SLOTS + entry[valid]) * nq,
            arrival[target[valid]],
            np.linalg.norm(
                corner_point[valid] - _edge_midpoints(abstraction, src_t[valid], entry[valid]),
                axis=1,
            ),
            point_letter[target[valid]],
            entered_letter[valid],
        )


def _add_arrivals_from_start(
    moves: _PassageMoves,
    abstraction: Abstraction,
    corners: _ArrivalCorners,
    source: IntArray,
    target: IntArray,
    arrival: IntArray,
    point_letter: IntArray,
    starts: tuple[StartCell, ...],
    start_point: tuple[float, float],
    nq: int,
) -> None:
    """Passages from the start, off both edges of its triangle through the vertex (a start
    on such an edge would slide along it, even while searching with bounces: refinement
    does not see the start's edges)."""
    src_t, src_k = corners.triangle[source], corners.corner[source]
    start_ok = np.zeros(len(source), dtype=bool)
    for cell in starts:
        blocked = np.zeros(3, dtype=bool)
        blocked[list(cell.blocked)] = True
        mine = src_t == cell.triangle
        through_blocked = blocked[(src_k + 1) % 3] | blocked[(src_k + 2) % 3]
        start_ok |= mine & ~through_blocked
    corner_point = abstraction.vertices[corners.vertex[source]]
    start_xy = np.asarray(start_point, dtype=np.float64)
    entered_letter = abstraction.letter_of[corners.triangle[target]]
    moves.add(
        (src_t[start_ok] * SLOTS + START_SLOT) * nq,
        arrival[target[start_ok]],
        np.linalg.norm(corner_point[start_ok] - start_xy[None, :], axis=1),
        point_letter[target[start_ok]],
        entered_letter[start_ok],
    )


def _add_departures(
    moves: _PassageMoves,
    abstraction: Abstraction,
    corners: _ArrivalCorners,
    arrival: IntArray,
    letters: _LetterIds,
    allowed: BoolArray,
    nq: int,
    *,
    bounces: bool,
    closed: bool,
) -> None:
    """Moves out of each cell through the edge opposite the vertex (any edge, with
    ``bounces``) into an allowed neighbour; under the closed convention they read the
    crossing letter first."""
    cell_t, cell_k = corners.triangle, corners.corner
    neighbors = abstraction.neighbors
    cells = np.arange(len(cell_t))
    exits = [cell_k, (cell_k + 1) % 3, (cell_k + 2) % 3] if bounces else [cell_k]
    for exit_edge in exits:
        n = neighbors[cell_t, exit_edge]
        valid = n >= 0
        valid[valid] &= allowed[n[valid]]
        t2, e2, n2 = cell_t[valid], exit_edge[valid], n[valid]
        back = neighbors[n2]
        slot = np.where(back[:, 0] == t2, 0, np.where(back[:, 1] == t2, 1, 2)).astype(np.int64)
        if closed:
            first = _crossing_letter_ids(abstraction, letters, t2, n2)
        else:
            first = np.full(len(t2), -1, dtype=np.int64)
        moves.add(
            arrival[cells[valid]],
            (n2 * SLOTS + slot) * nq,
            np.linalg.norm(
                _edge_midpoints(abstraction, t2, e2) - abstraction.vertices[corners.vertex[valid]],
                axis=1,
            ),
            first,
            abstraction.letter_of[n2],
        )


def _crossing_letter_ids(
    abstraction: Abstraction, letters: _LetterIds, left: IntArray, entered: IntArray
) -> IntArray:
    """The id of the crossing letter between each pair of adjacent triangles."""
    stride = len(abstraction.letters)
    pairs = abstraction.letter_of[left] * stride + abstraction.letter_of[entered]
    unique_pairs, inverse = np.unique(pairs, return_inverse=True)
    table = letters.letters
    crossing = np.array(
        [
            letters.id_of(crossing_letter(table[key // stride], table[key % stride]))
            for key in unique_pairs.tolist()
        ],
        dtype=np.int64,
    )
    ids: IntArray = crossing[inverse.reshape(-1)]
    return ids


class _WordReader:
    """The automaton's successors over words of one or two letters, by letter class:
    letters with one projection on the automaton's propositions share one row of the
    successor table (it caches it), so moves are grouped by classes, not by letters (maps
    have many)."""

    def __init__(self, automaton: Automaton, letters: list[Letter]) -> None:
        table = successor_table(automaton, letters)
        self.full = (1 << automaton.num_acc) - 1
        self.rows: list[list[tuple[tuple[int, int], ...]]] = []
        row_index: dict[int, int] = {}
        self.letter_class = np.empty(len(letters), dtype=np.int64)
        for index, row in enumerate(table):
            self.letter_class[index] = row_index.setdefault(id(row), len(self.rows))
            if self.letter_class[index] == len(self.rows):
                self.rows.append(row)

    def read(self, q: int, word: tuple[int, ...]) -> dict[int, bool]:
        """The states after reading ``word`` (letter classes) from ``q``, each with whether
        some run to it saw every acceptance set."""
        frontier: dict[int, int] = {q: 0}
        for cls in word:
            following: dict[int, int] = {}
            for state, mask in frontier.items():
                for q_next, mark in self.rows[cls][state]:
                    following[q_next] = following.get(q_next, 0) | mask | mark
            frontier = following
        return {state: mask == self.full for state, mask in frontier.items()}


@dataclass(slots=True)
class _EdgeBatches:
    """Product edges as batches of arrays (sources, targets, costs, acceptance marks)."""

    sources: list[IntArray] = field(default_factory=list)
    targets: list[IntArray] = field(default_factory=list)
    costs: list[FloatArray] = field(default_factory=list)
    marks: list[BoolArray] = field(default_factory=list)

    def add(self, source: IntArray, target: IntArray, cost: FloatArray, mark: bool) -> None:
        """Append a batch of edges that share one mark."""
        self.sources.append(source)
        self.targets.append(target)
        self.costs.append(cost)
        self.marks.append(np.full(len(source), mark))

    def __iadd__(self, other: _EdgeBatches) -> _EdgeBatches:
        self.sources += other.sources
        self.targets += other.targets
        self.costs += other.costs
        self.marks += other.marks
        return self


def _passage_edges(
    moves: _PassageMoves,
    reader: _WordReader,
    metric: str,
    nq: int,
    times: MoveTimes | None = None,
) -> _EdgeBatches:
    """The product edges of the passage moves: per kind of move (the classes of the letters
    it reads) and automaton state, one edge per successor state.  Under ``"time"`` a
    passage weighs its length at top speed (its pursuit runs at ``max_speed``)."""
    src_off = np.concatenate(moves.source)
    dst_off = np.concatenate(moves.target)
    lengths = np.concatenate(moves.length)
    if metric == "time" and times is not None:
        lengths = lengths * times.seconds_per_length()
    weight = np.ones(len(lengths)) if metric == "hops" else lengths + STUTTER_COST
    first = np.concatenate(moves.first)
    second = np.concatenate(moves.second)
    letter_class = reader.letter_class
    classes = len(reader.rows) + 1
    first_class = np.where(first >= 0, letter_class[np.maximum(first, 0)], -1)
    key = (first_class + 1) * classes + letter_class[second]
    kinds, kind_of = np.unique(key, return_inverse=True)
    kind_of = kind_of.reshape(-1)
    edges = _EdgeBatches()
    for index, kind in enumerate(kinds.tolist()):
        selected = np.flatnonzero(kind_of == index)
        x, y = kind // classes - 1, kind % classes
        word = (x, y) if x >= 0 else (y,)
        for q in range(nq):
            for q_next, accepting in reader.read(q, word).items():
                edges.add(
                    src_off[selected] + q, dst_off[selected] + q_next, weight[selected], accepting
                )
    return edges


def _arrival_stutter_edges(
    own: IntArray, arrival: IntArray, reader: _WordReader, stutter: BoolArray, nq: int
) -> _EdgeBatches:
    """Stutter in a cell: reading its triangle's letter (class ``own``) again.  Marks in
    ``stutter`` the nodes whose stutter loop accepts; staying in the same state is no edge."""
    edges = _EdgeBatches()
    for cls in np.unique(own).tolist():
        stays = np.flatnonzero(own == cls)
        for q in range(nq):
            for q_next, accepting in reader.read(q, (cls,)).items():
                if q_next == q:
                    if accepting:
                        stutter[arrival[stays] + q] = True
                    continue
                edges.add(
                    arrival[stays] + q,
                    arrival[stays] + q_next,
                    np.full(len(stays), STUTTER_COST),
                    accepting,
                )
    return edges


def _with_edges(product: Product, edges: _EdgeBatches, stutter: BoolArray, size: int) -> Product:
    """``product`` grown to ``size`` nodes with ``edges`` added, stable by source: every
    node's ordinary edges keep their order, passages come after."""
    old = product.graph
    new_src = np.concatenate(edges.sources) if edges.sources else np.zeros(0, dtype=np.int64)
    new_dst = np.concatenate(edges.targets) if edges.targets else np.zeros(0, dtype=np.int64)
    new_cost = np.concatenate(edges.costs) if edges.costs else np.zeros(0)
    new_mark = np.concatenate(edges.marks) if edges.marks else np.zeros(0, dtype=bool)
    graph, order = Graph.from_edges(
        np.concatenate([old.sources, new_src]),
        np.concatenate([old.targets, new_dst]),
        np.concatenate([old.weights, new_cost]),
        size,
    )
    accepting_edges = np.concatenate([product.accepting, new_mark])[order]
    return replace(
        product, graph=graph, accepting=accepting_edges, stutter_accepting=stutter, num_nodes=size
    )


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
