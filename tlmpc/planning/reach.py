"""Where the robot can go, and a cheap proof that no plan exists when that is too little.

The triangles the robot can reach from its start cross shared edges between triangles the
task's invariants allow and pass through mesh vertices (vertex passages,
:mod:`tlmpc.planning.passages`).  A breadth-first search over that graph costs a few array
operations per layer, while the search through vertex passages builds a product whose
passage edges grow with the square of the triangles around a vertex and is refused beyond a
budget (P060).  So before it, the planner asks whether the task can be accepted at all on the
letters the reachable triangles offer (:func:`cannot_accept_on_reach`): when it cannot, no
plan exists whatever the budget, and the explanation says which region is out of reach.

The reachable set is an over-approximation of what the product reaches (every passage joins
allowed triangles around one vertex), so a refusal from it is exact: no product search could
find a plan.  When it does not refuse, the product decides.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np
import numpy.typing as npt

from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.degeneralize import degeneralize
from tlmpc.automata.guards import holds
from tlmpc.automata.model import Automaton
from tlmpc.automata.simplify import trim
from tlmpc.ltl.ast import Formula
from tlmpc.planning.boundary import StartCell, start_point_label, task_letters
from tlmpc.planning.contacts import Letter, vertex_point_letters
from tlmpc.planning.model import POINT

BoolArray = npt.NDArray[np.bool_]


def passable_vertices(
    abstraction: Abstraction,
    required: Sequence[Formula],
    *,
    closed: bool,
    corner_letters: Mapping[int, Letter] | None = None,
) -> BoolArray:
    """Mesh vertices a trajectory may pass through under the invariants ``required``.

    Under the closed convention the instant at a contact vertex reads every region whose
    closure holds it, so a corner of a region the task forbids is no way through; under the
    right-continuous convention that instant reads the triangle entered.  ``corner_letters``:
    :func:`tlmpc.planning.contacts.vertex_point_letters` when the caller has it already.
    """
    passable = np.ones(abstraction.vertices.shape[0], dtype=bool)
    if closed and required:
        if corner_letters is None:
            corner_letters = vertex_point_letters(abstraction)
        for vertex, letter in corner_letters.items():
            if not all(holds(p, set(letter)) for p in required):
                passable[vertex] = False
    return passable


def reachable_triangles(
    abstraction: Abstraction,
    allowed: BoolArray,
    sources: Sequence[int],
    passable: BoolArray | None = None,
) -> BoolArray:
    """The ``allowed`` triangles reachable from the allowed ones of ``sources``, across
    shared edges and through the shared vertices where ``passable`` (a mask over the mesh
    vertices; None: every vertex) holds."""
    m = abstraction.num_triangles
    neighbors, triangles = abstraction.neighbors, abstraction.triangles
    seen = np.zeros(m, dtype=bool)
    start = np.asarray(list(sources), dtype=np.int64)
    frontier = np.unique(start[allowed[start]]) if len(start) else start
    seen[frontier] = True
    # The triangles around each vertex, as a compressed row table over the corners; a vertex
    # is crossed once (its whole fan is taken then) or never (not passable).
    corners = triangles.reshape(-1)
    order = np.argsort(corners, kind="stable")
    around = order // 3
    first = np.searchsorted(corners[order], np.arange(abstraction.vertices.shape[0] + 1))
    crossed = np.zeros(abstraction.vertices.shape[0], dtype=bool) if passable is None else ~passable
    # Breadth-first, one layer of triangles per round.
    while len(frontier):
        ahead = neighbors[frontier].reshape(-1)
        ahead = ahead[ahead >= 0]
        vertices = np.unique(triangles[frontier].reshape(-1))
        vertices = vertices[~crossed[vertices]]
        crossed[vertices] = True
        lengths = first[vertices + 1] - first[vertices]
        if lengths.sum():
            offsets = np.repeat(first[vertices] - np.cumsum(lengths) + lengths, lengths)
            ahead = np.concatenate([ahead, around[np.arange(lengths.sum()) + offsets]])
        ahead = np.unique(ahead[allowed[ahead] & ~seen[ahead]])
        seen[ahead] = True
        frontier = ahead
    return seen


def cannot_accept_on_reach(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    allowed: BoolArray,
    required: Sequence[Formula],
    starts: Sequence[StartCell],
    start_point: tuple[float, float],
    convention: str,
    resume: frozenset[int] | None = None,
) -> bool:
    """True when no accepting run of ``automaton`` reads only letters the robot can have
    where it can go: then no plan exists, through edges, U-turns or vertex passages.

    The letters are those the planner reads (:func:`tlmpc.planning.boundary.task_letters`)
    whose regions all occur on the reachable triangles, on the corners the closed convention
    reads there, or at the start point.  ``resume`` (a run under way, see
    :func:`tlmpc.planning.plan.plan`): the robot is in ``abstraction.start`` and the
    degeneralized automaton in one of these states.
    """
    closed = convention == "closed"
    sources = [abstraction.start] if resume is not None else [c.triangle for c in starts]
    corner_letters = vertex_point_letters(abstraction) if closed else {}
    passable = passable_vertices(
        abstraction, required, closed=closed, corner_letters=corner_letters
    )
    reached = reachable_triangles(abstraction, allowed, sources, passable)
    names = {
        name
        for index in np.unique(abstraction.letter_of[reached]).tolist()
        for name in abstraction.letters[index]
    }
    if closed:
        names.update(start_point_label(abstraction, start_point))
        corners = set(np.unique(abstraction.triangles[reached]).tolist())
        for vertex, letter in corner_letters.items():
            if vertex in corners:
                names.update(letter)
    names.add(POINT)
    aps = set(automaton.aps)
    offered = {
        frozenset(aps.intersection(letter))
        for letter in task_letters(abstraction, convention, start_point)
        if names.issuperset(letter)
    }
    working = automaton
    initial_states: Sequence[int] = [automaton.initial]
    if resume is not None:
        working = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
        initial_states = sorted(resume)
    enabled = tuple(e for e in working.edges if any(holds(e.guard, x) for x in offered))
    restricted = replace(working, edges=enabled)
    return not any(trim(replace(restricted, initial=q)).edges for q in initial_states)
