"""The planner's own shortest-path search against scipy's Dijkstra (the search it replaced).

scipy's ``dijkstra`` is the oracle here, never in tlmpc: distances must agree bit for bit on
every node; predecessors must follow the documented tie-break (smallest d(u), then smallest
u, among the edges attaining d(v)), which agrees with scipy's wherever that smallest d(u) is
unique (scipy orders equal keys by its heap).  At the plan level, the planner run with
scipy's search (the former planner) and with its own gives lassos of the same cost, and the
very same lasso whenever scipy's predecessors had no such tie.
"""

from __future__ import annotations

import itertools
import json
import sys
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import event, example, given, settings
from hypothesis import strategies as st
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from tlmpc.abstraction import build_abstraction
from tlmpc.automata import translate
from tlmpc.base.errors import InvalidInputError, NoPlanError
from tlmpc.base.graphs import strong_components
from tlmpc.mission import load_mission_text
from tlmpc.planning.plan import plan
from tlmpc.planning.search import Graph, closing_searches, distances, shortest_paths

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

# Few distinct weights: equal path lengths (exact ties) are common, as on a regular mesh.
WEIGHTS = (0.25, 0.5, 0.75, 1.0, 1e-9, 0.1 + 0.2)


def _scipy(graph: Graph, sources: IntArray, limit: float = np.inf) -> tuple[FloatArray, IntArray]:
    matrix = csr_matrix(
        (graph.weights.copy(), graph.targets.copy(), graph.indptr.copy()),
        shape=(graph.num_nodes, graph.num_nodes),
    )
    matrix.sort_indices()
    if len(sources) == 1:
        dist, pred = dijkstra(
            matrix, indices=int(sources[0]), return_predecessors=True, limit=limit
        )
    else:
        dist, pred, _ = dijkstra(
            matrix, indices=sources, min_only=True, return_predecessors=True, limit=limit
        )
    return np.asarray(dist), np.where(pred < 0, -1, pred).astype(np.int64)


def _rule_predecessor(graph: Graph, dist: FloatArray, v: int) -> int:
    """The tie-break's predecessor of v, by brute force over all edges."""
    offers = [
        (float(dist[u]), int(u))
        for u, t, w in zip(graph.sources, graph.targets, graph.weights, strict=True)
        if t == v and dist[u] + w == dist[v]
    ]
    return min(offers)[1]


@st.composite
def graphs(draw: Any) -> tuple[Graph, IntArray]:
    n = draw(st.integers(1, 24))
    pairs = draw(
        st.lists(
            st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)).filter(lambda p: p[0] != p[1]),
            unique=True,
            max_size=4 * n,
        )
    )
    weights = draw(st.lists(st.sampled_from(WEIGHTS), min_size=len(pairs), max_size=len(pairs)))
    src = np.array([p[0] for p in pairs], dtype=np.int64)
    dst = np.array([p[1] for p in pairs], dtype=np.int64)
    graph, _ = Graph.from_edges(src, dst, np.array(weights, dtype=np.float64), n)
    sources = np.array(
        sorted(draw(st.sets(st.integers(0, n - 1), min_size=1, max_size=3))), dtype=np.int64
    )
    return graph, sources


def _graph(edges: list[tuple[int, int, float]], n: int) -> Graph:
    src, dst, w = zip(*edges, strict=True)
    graph, _ = Graph.from_edges(
        np.array(src, dtype=np.int64), np.array(dst, dtype=np.int64), np.array(w), n
    )
    return graph


# A diamond: two equally far predecessors offer the same distance in the same round.
DIAMOND = _graph([(0, 1, 0.5), (0, 2, 0.5), (1, 3, 0.25), (2, 3, 0.25)], 4)
# A goal found while a nearer node is still to be searched from.
BEHIND = _graph([(0, 1, 0.25), (1, 2, 0.25), (0, 3, 0.5)], 4)
# The target is first offered by a long edge, then by a shorter way through a farther node.
SHORTCUT = _graph([(0, 3, 1.0), (0, 1, 0.75), (1, 3, 0.1)], 4)
ZERO = np.array([0], dtype=np.int64)


def _check_against_scipy(graph: Graph, sources: IntArray, limit: float) -> None:
    ours, pred = shortest_paths(graph, sources, limit=limit)
    theirs, their_pred = _scipy(graph, sources, limit)
    assert np.array_equal(ours, theirs), "distances are Dijkstra's, bit for bit"
    for v in range(graph.num_nodes):
        if not np.isfinite(ours[v]) or (ours[v] == 0.0 and v in sources):
            assert pred[v] == -1
            continue
        assert pred[v] == _rule_predecessor(graph, ours, v)
        if ours[their_pred[v]] != ours[pred[v]]:
            pytest.fail(f"scipy's predecessor of {v} is nearer: not a tie, yet different")
        if pred[v] != their_pred[v]:
            event("tie ordered differently from scipy's heap")


@given(graphs(), st.sampled_from([np.inf, 0.8, 2.0]))
@example((DIAMOND, ZERO), np.inf)
def test_distances_and_predecessors_match_dijkstra(
    case: tuple[Graph, IntArray], limit: float
) -> None:
    graph, sources = case
    _check_against_scipy(graph, sources, limit)
    _check_against_scipy(graph, sources[:1], limit)


# Many equal ways into one node: offers that tie at its new distance in one round.
FAN = _graph([(0, k, 0.5) for k in range(1, 6)] + [(k, 6, 0.25) for k in range(1, 6)], 7)


@given(graphs())
@example((DIAMOND, ZERO))
@example((FAN, ZERO))
def test_distances_without_predecessors_are_dijkstras(case: tuple[Graph, IntArray]) -> None:
    """The search without predecessors (the guided search's bounds): Dijkstra's distances bit
    for bit, from one source and from several."""
    graph, sources = case
    for chosen in (sources, sources[:1]):
        theirs, _ = _scipy(graph, chosen)
        ours = distances(graph, chosen)
        assert ours.view(np.int64).tolist() == theirs.view(np.int64).tolist()


@given(graphs(), st.data())
def test_search_stops_at_the_nearest_goal_with_exact_distances_before_it(
    case: tuple[Graph, IntArray], data: st.DataObject
) -> None:
    graph, sources = case
    goals = np.array(
        data.draw(st.lists(st.booleans(), min_size=graph.num_nodes, max_size=graph.num_nodes)),
        dtype=bool,
    )
    _check_goal_stop(graph, sources, goals)


def test_search_goes_on_from_nodes_nearer_than_the_goal() -> None:
    _check_goal_stop(BEHIND, ZERO, np.array([False, False, False, True]))


def _check_goal_stop(graph: Graph, sources: IntArray, goals: npt.NDArray[np.bool_]) -> None:
    full, full_pred = shortest_paths(graph, sources)
    stopped, stopped_pred = shortest_paths(graph, sources, goals=goals)
    nearest = float(full[goals].min()) if goals.any() else np.inf
    kept = full <= nearest
    assert np.array_equal(stopped[kept], full[kept])
    assert np.array_equal(stopped_pred[kept], full_pred[kept])
    assert np.isinf(stopped[~kept]).all()
    assert (stopped_pred[~kept] == -1).all()


@given(graphs(), st.data())
@example((DIAMOND, ZERO), None)
@example((SHORTCUT, ZERO), None)
def test_batched_closing_searches_are_single_searches(
    case: tuple[Graph, IntArray], data: st.DataObject | None
) -> None:
    graph, _ = case
    n = graph.num_nodes
    if data is None:  # from the source to the sink and back, with and without a limit
        starts, targets, limits = [0, 3, 0], [3, 0, 3], [np.inf, np.inf, 0.5]
    else:
        size = data.draw(st.integers(1, 5))
        nodes = st.lists(st.integers(0, n - 1), min_size=size, max_size=size)
        starts, targets = data.draw(nodes), data.draw(nodes)
        limits = data.draw(
            st.lists(st.sampled_from([np.inf, 0.3, 1.0]), min_size=size, max_size=size)
        )
    distances, paths = closing_searches(
        graph, np.array(starts), np.array(targets), np.array(limits)
    )
    for k, (start, target, limit) in enumerate(zip(starts, targets, limits, strict=True)):
        goal = np.zeros(n, dtype=bool)
        goal[target] = True
        dist, pred = shortest_paths(graph, np.array([start]), limit=limit, goals=goal)
        assert distances[k] == dist[target] or (np.isinf(distances[k]) and np.isinf(dist[target]))
        path = [target] if np.isfinite(dist[target]) else []
        while path and pred[path[-1]] >= 0:
            path.append(int(pred[path[-1]]))
        assert paths[k] == path[::-1]


@given(graphs(), st.data())
def test_path_weights_are_the_edges_weights(
    case: tuple[Graph, IntArray], data: st.DataObject
) -> None:
    graph, _ = case
    edges = {
        (int(u), int(v)): float(w)
        for u, v, w in zip(graph.sources, graph.targets, graph.weights, strict=True)
    }
    walk: list[int] = [data.draw(st.integers(0, graph.num_nodes - 1))]
    for _ in range(data.draw(st.integers(0, 8))):
        # Mostly along an edge; now and then to any node (an edge that may not exist).
        ahead = [v for (u, v) in edges if u == walk[-1]]
        if ahead and data.draw(st.integers(0, 9)) > 0:
            walk.append(data.draw(st.sampled_from(ahead)))
        else:
            walk.append(data.draw(st.integers(0, graph.num_nodes - 1)))
    pairs = list(itertools.pairwise(walk))
    if all(pair in edges for pair in pairs):
        event("a path")
        assert graph.path_weights(walk) == [edges[pair] for pair in pairs]
    else:
        event("a missing edge")
        with pytest.raises(KeyError):
            graph.path_weights(walk)


@given(graphs())
def test_strong_components_match_scipy(case: tuple[Graph, IntArray]) -> None:
    from scipy.sparse.csgraph import connected_components

    graph, _ = case
    ours = np.asarray(strong_components(graph.indptr, graph.targets))
    matrix = csr_matrix(
        (graph.weights.copy(), graph.targets.copy(), graph.indptr.copy()),
        shape=(graph.num_nodes, graph.num_nodes),
    )
    _, theirs = connected_components(matrix, directed=True, connection="strong")
    # Same partition: labels correspond one to one.
    pairs = set(zip(ours.tolist(), theirs.tolist(), strict=True))
    assert len(pairs) == len(set(ours.tolist())) == len(set(theirs.tolist()))


TASKS = (
    "visit a",
    "visit a then b",
    "visit a, b and c",
    "patrol a, b",
    "visit b while avoiding c",
    "stay in b",
    "whenever a, visit b",
    "visit a infinitely often",
)


def _mission(task: str, rects: list[tuple[int, int, int, int]], cost: str, beta: float) -> str:
    regions = "\n".join(
        f"  {name}: {{rect: [{x0}, {y0}, {x0 + w}, {y0 + h}]}}"
        for name, (x0, y0, w, h) in zip("abc", rects, strict=True)
    )
    return (
        "version: 1\nworkspace:\n  boundary: {rect: [0, 0, 10, 8]}\n"
        f"regions:\n{regions}\nrobot: {{start: [0.5, 0.5]}}\n"
        f"task: [{json.dumps(task)}]\n"
        f"options: {{cost: {cost}, beta: {beta}, min_angle: null, max_area: null}}\n"
    )


rects = st.tuples(st.integers(0, 8), st.integers(0, 6), st.integers(1, 3), st.integers(1, 3))


@settings(max_examples=max(10, settings().max_examples // 4))
@given(
    st.sampled_from(TASKS),
    st.lists(rects, min_size=3, max_size=3),
    st.sampled_from(["length", "hops"]),
    st.sampled_from([0.5, 1.0, 3.0]),
)
def test_plan_is_the_former_scipy_planners(
    task: str, regions: list[tuple[int, int, int, int]], cost: str, beta: float
) -> None:
    try:
        mission = load_mission_text(_mission(task, regions, cost, beta), "m.yaml")
    except InvalidInputError:
        event("invalid map")
        return
    built = build_abstraction(mission)
    automaton = translate(mission.formula, letters=built.letters)
    tied: list[bool] = []

    def former(
        graph: Graph, sources: IntArray, *, limit: float = np.inf, goals: object = None
    ) -> tuple[FloatArray, IntArray]:
        # The former search: scipy's Dijkstra over the whole product, no early end.
        dist, pred = _scipy(graph, sources, limit)
        own_dist, own_pred = shortest_paths(graph, sources, limit=limit)
        assert np.array_equal(dist, own_dist)
        tied.append(not np.array_equal(pred, own_pred))
        return dist, pred

    def former_closing(
        graph: Graph, starts: IntArray, targets: IntArray, limits: FloatArray
    ) -> tuple[FloatArray, list[list[int]]]:
        # One scipy search per candidate, as the former planner closed them.
        distances, paths = [], []
        for start, target, limit in zip(starts, targets, limits, strict=True):
            dist, pred = former(graph, np.array([start]), limit=float(limit))
            distances.append(dist[target])
            path = [int(target)] if np.isfinite(dist[target]) else []
            while path and pred[path[-1]] >= 0:
                path.append(int(pred[path[-1]]))
            paths.append(path[::-1])
        return np.array(distances), paths

    def run() -> Any:
        try:
            return plan(
                built,
                automaton,
                formula=mission.formula,
                options=mission.options,
                start_point=mission.robot.start,
            )
        except NoPlanError:
            return None

    ours = run()
    plan_module: Any = sys.modules["tlmpc.planning.plan"]
    originals = plan_module.shortest_paths, plan_module.closing_searches
    plan_module.shortest_paths, plan_module.closing_searches = former, former_closing
    try:
        theirs = run()
    finally:
        plan_module.shortest_paths, plan_module.closing_searches = originals
    assert (ours is None) == (theirs is None)
    if ours is None:
        event("no plan")
        return
    assert ours.cost == theirs.cost
    assert (ours.prefix_cost, ours.cycle_cost) == (theirs.prefix_cost, theirs.cycle_cost)
    assert ours.stats["optimal"] == theirs.stats["optimal"]
    if any(tied):
        event("scipy met an exact tie: same cost, its own choice")
        return
    event("no tie: the same lasso")
    assert (ours.prefix, ours.cycle) == (theirs.prefix, theirs.cycle)
    assert (ours.prefix_states, ours.cycle_states) == (theirs.prefix_states, theirs.cycle_states)
