"""The numpy product equals the product of its definition, built edge by edge in plain Python.

The reference below reads docs/planning.md's definition directly: a node is (triangle, entry
slot, automaton state); a move leaves a triangle through any edge but its entry edge (any edge
with bounces; at the start, not through an edge holding the start point unless bouncing) into
an allowed neighbour, costs the distance between the midpoints of the entry and exit edges
(from the start point in the start slot) or one hop, and takes the automaton along every run
over the entered triangle's label (under the closed convention the crossing instant's label
first); stuttering reads the triangle's label again.  Random automata (nondeterministic, with
several acceptance sets and guards over the regions and the point marker) exercise every way
a node's out-degree can vary between kinds of moves and automaton states.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any
from unittest import mock

import numpy as np
import numpy.typing as npt
from hypothesis import event, given, settings
from hypothesis import strategies as st
from starts import start_triangles

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.model import Abstraction
from tlmpc.abstraction.starts import StartCell
from tlmpc.automata.model import Automaton, Edge
from tlmpc.ltl.ast import FALSE, TRUE, And, Formula, Not, Or, Prop
from tlmpc.mission import load_mission_text
from tlmpc.planning import product as product_module
from tlmpc.planning.boundary import POINT
from tlmpc.planning.product import INT32_LIMIT, Product, build_product, index_dtype

APS = ("a", "b", "c")
SLOTS, START = 4, 3

MAPS = (
    # Overlapping regions and a hole.
    "workspace: {boundary: {rect: [0, 0, 6, 4]}, holes: [{rect: [2.5, 1.5, 3.5, 2.5]}]}\n"
    "regions: {a: {rect: [0, 0, 2, 2]}, b: {rect: [1, 1, 3, 3.5]}, c: {rect: [4, 0, 6, 4]}}\n",
    # Regions touching at a corner, and free space around them.
    "workspace: {boundary: {rect: [0, 0, 5, 5]}}\n"
    "regions: {a: {rect: [1, 1, 2.5, 2.5]}, b: {rect: [2.5, 2.5, 4, 4]},\n"
    "  c: {rect: [0, 4, 1, 5]}}\n",
)


@cache
def _map(index: int) -> Abstraction:
    text = (
        "version: 1\n" + MAPS[index] + "robot: {start: [0.5, 0.5]}\ntask: ['visit a']\n"
        "options: {min_angle: null, max_area: null}\n"
    )
    return build_abstraction(load_mission_text(text, "m.yaml"))


def guards() -> st.SearchStrategy[Formula]:
    names: list[Formula] = [Prop(p) for p in (*APS, POINT)]
    leaves: st.SearchStrategy[Formula] = st.sampled_from([TRUE, FALSE, *names])
    return st.recursive(
        leaves,
        lambda inner: st.one_of(
            st.builds(Not, inner),
            st.builds(lambda x, y: And((x, y)), inner, inner),
            st.builds(lambda x, y: Or((x, y)), inner, inner),
        ),
        max_leaves=4,
    )


@st.composite
def automata(draw: st.DrawFn) -> Automaton:
    states = draw(st.integers(1, 4))
    num_acc = draw(st.integers(0, 2))
    edges = draw(
        st.lists(
            st.builds(
                lambda src, dst, guard, marks: Edge(
                    src=src, dst=dst, guard=guard, marks=frozenset(marks)
                ),
                st.integers(0, states - 1),
                st.integers(0, states - 1),
                guards(),
                st.sets(st.integers(0, num_acc - 1)) if num_acc else st.just(set[int]()),
            ),
            min_size=1,
            max_size=3 * states,
        )
    )
    return Automaton(
        aps=(*APS, POINT), num_states=states, initial=0, edges=tuple(edges), num_acc=num_acc
    )


def _mask(edge: Edge) -> int:
    return sum(1 << mark for mark in edge.marks)


def _read(automaton: Automaton, q: int, word: list[set[str]]) -> dict[int, bool]:
    """Every run from q over word: its end state, accepting when some run to it sees every
    acceptance set."""
    runs = {(q, 0)}
    for letter in word:
        runs = {
            (edge.dst, mask | _mask(edge))
            for state, mask in runs
            for edge in automaton.edges
            if edge.src == state and _holds(edge.guard, letter)
        }
    full = (1 << automaton.num_acc) - 1
    ends: dict[int, bool] = {}
    for state, mask in runs:
        ends[state] = ends.get(state, False) or mask == full
    return ends


def _holds(guard: Formula, letter: set[str]) -> bool:
    if isinstance(guard, Prop):
        return guard.name in letter
    if isinstance(guard, Not):
        return not _holds(guard.arg, letter)
    if isinstance(guard, And):
        return all(_holds(part, letter) for part in guard.args)
    if isinstance(guard, Or):
        return any(_holds(part, letter) for part in guard.args)
    return guard == TRUE


def _midpoint(abstraction: Abstraction, t: int, i: int) -> tuple[float, float]:
    corners = [abstraction.vertices[int(v)] for v in abstraction.triangles[t]]
    a, b = corners[(i + 1) % 3], corners[(i + 2) % 3]
    return (float(a[0]) + float(b[0])) / 2.0, (float(a[1]) + float(b[1])) / 2.0


def reference(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    allowed: list[bool],
    start_point: tuple[float, float],
    metric: str,
    starts: tuple[StartCell, ...],
    closed: bool,
    start_label: tuple[str, ...],
    bounces: bool,
) -> tuple[dict[tuple[int, int], tuple[float, bool]], set[int], set[int]]:
    """Edges {(u, v): (weight, accepting)}, accepting stutter nodes and initial nodes."""
    nq = automaton.num_states
    label = [set(abstraction.labels(t)) for t in range(abstraction.num_triangles)]
    blocked = {cell.triangle: set(cell.blocked) for cell in starts}
    edges: dict[tuple[int, int], tuple[float, bool]] = {}
    stutter: set[int] = set()
    for t in range(abstraction.num_triangles):
        if not allowed[t]:
            continue
        around = [int(n) for n in abstraction.neighbors[t]]
        for s in range(SLOTS):
            if s == START and t not in blocked:
                continue
            node = (t * SLOTS + s) * nq
            for i, n in enumerate(around):
                if n < 0 or not allowed[n] or (i == s and not bounces):
                    continue
                if s == START and i in blocked[t] and not bounces:
                    continue
                if metric == "hops":
                    weight = 1.0
                else:
                    x0, y0 = start_point if s == START else _midpoint(abstraction, t, s)
                    x1, y1 = _midpoint(abstraction, t, i)
                    dx, dy = x1 - x0, y1 - y0
                    weight = math.sqrt(dx * dx + dy * dy) + 1e-9
                entry = [int(x) for x in abstraction.neighbors[n]].index(t)
                word = [label[t] | label[n] | {POINT}, label[n]] if closed else [label[n]]
                for q in range(nq):
                    for q_next, accepting in _read(automaton, q, word).items():
                        edges[node + q, (n * SLOTS + entry) * nq + q_next] = (weight, accepting)
            if s != START and around[s] < 0:
                continue  # no entry edge there: no node to stay in
            for q in range(nq):
                for q_next, accepting in _read(automaton, q, [label[t]]).items():
                    if q_next != q:
                        edges[node + q, node + q_next] = (1e-9, accepting)
                    elif accepting:
                        stutter.add(node + q)
    first = [automaton.initial]
    if closed:
        first = list(_read(automaton, automaton.initial, [{*start_label, POINT}]))
    initial = {
        (cell.triangle * SLOTS + START) * nq + q
        for cell in starts
        if allowed[cell.triangle]
        for q0 in first
        for q in _read(automaton, q0, [label[cell.triangle]])
    }
    return edges, stutter, initial


def _edges(product: Product) -> dict[tuple[int, int], tuple[float, bool]]:
    graph = product.graph
    assert graph.indptr[0] == 0
    assert graph.indptr[-1] == graph.nnz
    assert (np.diff(graph.indptr) >= 0).all()
    runs = np.repeat(np.arange(graph.num_nodes), np.diff(graph.indptr))
    assert np.array_equal(runs, graph.sources), "edges grouped by source, as indptr says"
    assert np.array_equal(graph.source_of(np.arange(graph.nnz)), runs), "tails looked up"
    found = {
        (int(u), int(v)): (float(w), bool(a))
        for u, v, w, a in zip(
            graph.sources, graph.targets, graph.weights, product.accepting, strict=True
        )
    }
    assert len(found) == graph.nnz, "no parallel product edges"
    return found


def _start_points(abstraction: Abstraction) -> st.SearchStrategy[tuple[float, float]]:
    """Inside a triangle, on an edge (two start triangles) or at a mesh vertex (a fan)."""
    corners = abstraction.vertices[abstraction.triangles]
    inside = [tuple(map(float, c.mean(axis=0))) for c in corners]
    on_edge = [tuple(map(float, (c[0] + c[1]) / 2.0)) for c in corners]
    vertex = [tuple(map(float, c[0])) for c in corners]
    return st.sampled_from([*inside, *on_edge, *vertex])


@settings(max_examples=max(20, settings().max_examples // 2))
@given(st.data(), automata(), st.booleans(), st.booleans(), st.sampled_from(["length", "hops"]))
def test_product_is_its_definition(
    data: st.DataObject, automaton: Automaton, closed: bool, bounces: bool, metric: str
) -> None:
    abstraction = _map(data.draw(st.integers(0, len(MAPS) - 1)))
    m = abstraction.num_triangles
    # Most tasks allow the whole map; a few triangles are cut out by an invariant.
    cut = data.draw(st.sets(st.integers(0, m - 1), max_size=m // 3))
    allowed = [t not in cut for t in range(m)]
    start = data.draw(_start_points(abstraction))
    starts = tuple(
        StartCell(triangle=t, blocked=tuple(sorted(edges)))
        for t, edges in sorted(start_triangles(abstraction, start).items())
    )
    start_label = tuple(sorted(data.draw(st.sets(st.sampled_from(APS)))))
    kwargs: dict[str, Any] = {"start_point": start, "metric": metric, "starts": starts}
    # Numbers from the 32-bit limit on are held in 64 bits: the limit moved down to this
    # product's node count (or below) takes the 64-bit way here, which must give the same.
    size = m * SLOTS * automaton.num_states
    limit = data.draw(st.sampled_from([INT32_LIMIT, 0, size - 1, size]))
    with mock.patch.object(product_module, "INT32_LIMIT", limit):
        product = build_product(
            abstraction,
            automaton,
            allowed=np.array(allowed, dtype=bool),
            convention="closed" if closed else "right",
            start_label=start_label,
            bounces=bounces,
            **kwargs,
        )
    narrow = np.dtype(np.int32)
    assert (product.graph.targets.dtype == narrow) == (size <= limit)
    assert (product.graph.sources.dtype == narrow) == (size <= limit)
    assert (product.graph.indptr.dtype == narrow) == (product.graph.nnz + 1 <= limit)
    edges, stutter, initial = reference(
        abstraction,
        automaton,
        allowed=allowed,
        closed=closed,
        start_label=start_label,
        bounces=bounces,
        **kwargs,
    )
    assert product.num_nodes == m * SLOTS * automaton.num_states
    event("no edges" if not edges else "under 100 edges" if len(edges) < 100 else "edges")
    event(f"starts {len(starts)}")
    assert _edges(product) == edges  # weights bit for bit
    stays: npt.NDArray[np.int64] = np.flatnonzero(product.stutter_accepting)
    assert set(stays.tolist()) == stutter
    assert product.initial.tolist() == sorted(initial)


def test_numbers_past_32_bits_are_held_in_64() -> None:
    assert index_dtype(2**31) is np.int32  # 0 .. 2**31 - 1: the largest int32 is the last
    assert index_dtype(2**31 + 1) is np.int64
    assert index_dtype(2**40) is np.int64
    assert np.iinfo(np.int32).max == INT32_LIMIT - 1
