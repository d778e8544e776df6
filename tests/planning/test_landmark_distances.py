"""The guided search's distances on the transition system (scipy's compiled Dijkstra) against
independent computations:

* on random graphs (parallel edges, nodes without edges, weights from 1e-3 to 1e3, empty and
  overlapping goal sets) :func:`distances_to` equals, bit for bit, the numpy delta-stepping
  search :func:`~tlmpc.planning.search.shortest_paths` and a brute-force Bellman-Ford (plain
  Python floats, the same sums ``d(u) + w``);
* on missions, every landmark column of the region-level graph is the numpy search's distance
  to entering that landmark, and a closing target's distances are its search's.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_guided import _inputs, _load

from tlmpc.planning.bounds import distances_to, region_graph
from tlmpc.planning.lazy import lazy_product
from tlmpc.planning.product import SLOTS
from tlmpc.planning.search import Graph, shortest_paths


def _bellman_ford(n: int, edges: list[tuple[int, int, float]], goal: list[int]) -> list[float]:
    """Distances from the nearest goal: relax every edge until nothing changes."""
    distance = [np.inf] * n
    for node in goal:
        distance[node] = 0.0
    changed = True
    while changed:
        changed = False
        for u, v, w in edges:
            if distance[u] + w < distance[v]:
                distance[v] = distance[u] + w
                changed = True
    return distance


@st.composite
def graphs(draw: st.DrawFn) -> tuple[int, list[tuple[int, int, float]], list[list[int]]]:
    n = draw(st.integers(1, 14))
    node = st.integers(0, n - 1)
    weight = st.floats(1e-3, 1e3, allow_nan=False, allow_infinity=False)
    edges = draw(st.lists(st.tuples(node, node, weight), max_size=40))
    goals = draw(st.lists(st.lists(node, max_size=4, unique=True), min_size=1, max_size=3))
    return n, edges, goals


@settings(max_examples=150, deadline=None)
@given(graphs())
def test_distances_to_equals_the_numpy_search_and_bellman_ford(
    case: tuple[int, list[tuple[int, int, float]], list[list[int]]],
) -> None:
    n, edges, goals = case
    sources = np.array([u for u, _, _ in edges], dtype=np.int64)
    targets = np.array([v for _, v, _ in edges], dtype=np.int64)
    weights = np.array([w for _, _, w in edges], dtype=np.float64)
    graph, _ = Graph.from_edges(sources, targets, weights, n)
    found = distances_to(graph, [np.array(goal, dtype=np.int64) for goal in goals])
    assert found.shape == (n, len(goals))
    for index, goal in enumerate(goals):
        ours, _ = shortest_paths(graph, np.array(goal, dtype=np.int64))
        assert np.array_equal(found[:, index], ours)
        assert found[:, index].tolist() == _bellman_ford(n, edges, goal)


@pytest.mark.parametrize("spec", ["example1", "patrol", "far-cycle"])
def test_landmark_columns_are_the_numpy_searches_to_entering_each_landmark(spec: str) -> None:
    mission = _load(spec)
    abstraction, working, arguments = _inputs(mission, False)
    lazy = lazy_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    allowed = np.repeat(arguments["allowed"], SLOTS)  # type: ignore[call-overload]
    graph = region_graph(lazy, allowed)
    cells = lazy.num_cells
    entered = np.ones(cells, dtype=bool)
    entered[SLOTS - 1 :: SLOTS] = False
    assert len(graph.landmarks)
    for index, landmark in enumerate(graph.landmarks.tolist()):
        goal = np.flatnonzero(entered & (graph.cell_local == landmark))
        expected, _ = shortest_paths(graph.backwards, goal)
        assert np.array_equal(graph.distance[:, index], expected)
    some = np.flatnonzero(allowed)[:: max(1, int(allowed.sum()) // 5)]
    for cell in some.tolist():
        expected, _ = shortest_paths(graph.backwards, np.array([cell]))
        assert np.array_equal(graph.distance_to(np.array([cell])), expected)
