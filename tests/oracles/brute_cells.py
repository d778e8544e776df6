"""Brute-force oracle for plans on convex cells: every lasso of cell visits, by definition.

Re-states docs/control.md ("Convex cells") at the level of cells, without tlmpc's product,
cell product or searches. The cells are the partition's (``Cells.cell_of``), and each cell
move's and stay's width is the partition's (``Cells.move`` and ``Cells.stay``, compared with
an independent LP in tests/control/test_cells.py); what is re-stated here is which lassos a
plan on cells may be:

* two cells are adjacent when a mesh edge joins a triangle of each (read from the mesh's
  neighbour array);
* a run is a sequence of cell visits: a visit reads its cell's label (the right-continuous
  convention: the label of the cell entered), any number of times (stutter); the next
  visit is of an adjacent cell, **not the one this visit was entered from** (the start's
  cell is entered from nowhere), through the move's width;
* a cycle of visits that never leaves one cell is that cell's stay, through its stay width.

The automaton is read explicitly (guards by ``holds``, an edge accepting when it carries every
mark), in nodes (cell, entered from, state). At a floor w, a lasso exists when an accepting
edge u -> v of width >= w is reached from the start along such edges and v reaches u again,
some node of those cycles lying in another cell (the cycle moves), or every one in u's cell
and that cell's stay at least w wide (a stay); or an accepting stutter self-loop is reached in
a cell whose stay is at least w wide. Every width that occurs is tried as a floor, one after
the other (no bisection, no components).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from brute_bottleneck import reach
from starts import start_triangles

from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.guards import holds
from tlmpc.automata.model import Automaton
from tlmpc.planning.cells import Cells

#: (cell, the cell it was entered from or -1 at the start, automaton state)
Node = tuple[int, int, int]
#: node -> successor -> (width, carries the mark)
Edges = dict[Node, dict[Node, tuple[float, bool]]]


def adjacent_cells(abstraction: Abstraction, cells: Cells) -> dict[int, set[int]]:
    """Per cell, the cells across its mesh edges."""
    cell_of = [int(c) for c in cells.cell_of]
    found: dict[int, set[int]] = {c: set() for c in set(cell_of)}
    for t, row in enumerate(abstraction.neighbors.tolist()):
        for there in row:
            if there >= 0 and cell_of[there] != cell_of[t]:
                found[cell_of[t]].add(cell_of[there])
    return found


def product_graph(
    abstraction: Abstraction, cells: Cells, automaton: Automaton, start_point: Sequence[float]
) -> tuple[Edges, list[Node]]:
    """The reachable cell-level product and its initial nodes (the start must lie inside one
    triangle, off its edges)."""
    held = start_triangles(abstraction, start_point)
    assert len(held) == 1, "the start lies on an edge: the oracle does not model that"
    ((start, blocked),) = held.items()
    assert not blocked
    full = frozenset(range(automaton.num_acc))
    label = {int(c): set(abstraction.labels(t)) for t, c in enumerate(cells.cell_of.tolist())}
    near = adjacent_cells(abstraction, cells)

    def read(q: int, cell: int) -> list[tuple[int, bool]]:
        return [
            (e.dst, e.marks == full)
            for e in automaton.edges
            if e.src == q and holds(e.guard, label[cell])
        ]

    first = int(cells.cell_of[start])
    roots = sorted({(first, -1, dst) for dst, _ in read(automaton.initial, first)})
    graph: Edges = {}
    stack = list(roots)
    while stack:
        node = stack.pop()
        if node in graph:
            continue
        cell, entry, q = node
        out: dict[Node, tuple[float, bool]] = {}
        for dst, mark in read(q, cell):  # stutter: read the cell's label again
            key = (cell, entry, dst)
            out[key] = (math.inf, mark or out.get(key, (0.0, False))[1])
        for there in sorted(near[cell]):
            if there == entry:
                continue  # no turning back across the interface the robot came in by
            width = cells.move(cell, there).width
            for dst, mark in read(q, there):
                key = (there, cell, dst)
                out[key] = (width, mark or out.get(key, (0.0, False))[1])
        graph[node] = out
        stack.extend(out)
    return graph, roots


def has_lasso(cells: Cells, graph: Edges, roots: list[Node], floor: float) -> bool:
    """Whether some lasso of cell visits has every step at least ``floor`` wide (see the
    module doc)."""
    reached = reach(graph, roots, floor, reverse=False)
    for u, out in graph.items():
        if u not in reached:
            continue
        for v, (width, accepting) in out.items():
            if not accepting or width < floor:
                continue
            stay = cells.stay(u[0]).width >= floor
            if u == v:
                if stay:
                    return True
                continue
            back = reach(graph, [v], floor, reverse=False)
            if u not in back:
                continue
            on_cycles = back & reach(graph, [u], floor, reverse=True)
            if any(node[0] != u[0] for node in on_cycles):
                return True  # a cycle through u -> v that leaves u's cell
            if stay:
                return True  # cycles inside one cell: its stay
    return False


def widest_lasso(
    abstraction: Abstraction, cells: Cells, automaton: Automaton, start_point: Sequence[float]
) -> float | None:
    """The largest floor w with a lasso of cell visits at least w wide (None: no lasso)."""
    graph, roots = product_graph(abstraction, cells, automaton, start_point)
    candidates = {width for out in graph.values() for width, _ in out.values()}
    candidates |= {cells.stay(c).width for c in range(len(cells.cells))}
    best: float | None = None
    for floor in sorted(w for w in candidates if math.isfinite(w)):
        if has_lasso(cells, graph, roots, floor):
            best = floor
    return best
