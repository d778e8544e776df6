"""Closing searches side by side in the guided search, each against an independent computation.

* searches run side by side (a bucket queue per copy) settle every node of every copy at
  scipy's Dijkstra distance from that copy's own sources (each with its offset);
* the stacked closing bound gives, node for node, what a plain per-node evaluation of the
  bound's definition gives (a Python loop over the landmarks);
* a copy's limit from the other copies' lassos is what the brute-force minimum over the
  others allows (never the copy's own lasso, ties kept);
* the guided lasso costs what the built product gives with the searches one by one, side by
  side, and with candidates that never wait or wait long.
"""

from __future__ import annotations

from pathlib import Path
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra
from test_guided import TASKS, _costs_agree, _inputs, _load, _mission_text, _rooms_text, rects

import tlmpc.planning.guided as guided
from tlmpc.base.errors import InvalidInputError
from tlmpc.mission import load_mission_text
from tlmpc.planning.bounds import SAFETY, region_graph
from tlmpc.planning.guided import GuidedSearch, _Arrays, _Bounds, _others_limit
from tlmpc.planning.lazy import lazy_product
from tlmpc.planning.product import SLOTS, Product, build_product

ROOT = Path(__file__).resolve().parents[2]


def _from_sources(product: Product, sources: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """scipy's Dijkstra from a virtual node joined to each source by an edge of its offset."""
    graph = product.graph
    n = product.num_nodes
    rows = np.concatenate([graph.sources, np.full(len(sources), n)])
    cols = np.concatenate([graph.targets, sources])
    # An offset of 0 would be no edge in a sparse matrix: every offset is shifted by one.
    weights = np.concatenate([graph.weights, offsets + 1.0])
    matrix = csr_matrix((weights, (rows, cols)), shape=(n + 1, n + 1))
    distance: np.ndarray = dijkstra(matrix, indices=n)[:n] - 1.0
    return distance


@pytest.mark.parametrize("spec", ["example1", "patrol", "far-cycle"])
@pytest.mark.parametrize("bounded", [False, True])
def test_searches_side_by_side_settle_each_copy_at_dijkstras_distances(
    spec: str, bounded: bool
) -> None:
    mission = _load(spec)
    abstraction, working, arguments = _inputs(mission, False)
    product = build_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    lazy = lazy_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    size = lazy.num_nodes
    allowed = np.repeat(arguments["allowed"], SLOTS)  # type: ignore[call-overload]
    # Sources among the nodes the plan can reach (others may lead nowhere).
    start = _from_sources(product, lazy.initial, np.zeros(len(lazy.initial)))
    reachable = np.flatnonzero(np.isfinite(start))
    rng = np.random.default_rng(7)
    groups = [np.unique(rng.choice(reachable, 3)) for _ in range(3)]
    offsets = [rng.uniform(0.0, 2.0, len(group)) for group in groups]
    targets = [int(rng.choice(reachable)) for _ in groups]
    bounds = _Bounds(lazy, region_graph(lazy, allowed), 1.0)
    if bounded:
        bound = bounds.closings(targets, size)
    else:

        def bound(nodes: np.ndarray) -> np.ndarray:
            return np.zeros(len(nodes))

    sources = np.concatenate([group + k * size for k, group in enumerate(groups)])
    search = GuidedSearch(
        lazy,
        _Arrays.of(size * len(groups)),
        sources,
        bound,
        offsets=np.concatenate(offsets),
        copy_size=size,
        copies=len(groups),
    )
    rounds = 0
    arrays = search.arrays
    while np.isfinite(search.lowest()):
        # exhausted() against every queued node of every copy: a copy with a node below its
        # ceiling is not done.
        waiting = np.flatnonzero(arrays.seen & arrays.queued)
        f = arrays.dist[waiting] + arrays.estimate[waiting]
        least = np.full(len(groups), np.inf)
        np.minimum.at(least, waiting // size, f)
        assert search.exhausted(least)
        for k in np.flatnonzero(np.isfinite(least)).tolist():
            above = least.copy()
            above[k] = np.nextafter(above[k], np.inf)
            assert not search.exhausted(above)
        search.step()
        rounds += 1
    assert rounds > 1
    found = search.arrays.distance(np.arange(size * len(groups))).reshape(len(groups), size)
    for k, group in enumerate(groups):
        exact = _from_sources(product, group, offsets[k])
        # The bound of copy k is its own target's: nodes it calls hopeless are cut off.
        hopeless = ~np.isfinite(bound(np.arange(size) + k * size))
        check = ~hopeless & np.isfinite(found[k])
        assert check.sum() > size // 20
        assert np.allclose(found[k][check], exact[check], rtol=1e-12, atol=1e-12)
        if not bounded:
            assert np.array_equal(np.isfinite(found[k]), np.isfinite(exact))


@pytest.mark.parametrize("spec", ["example1", "patrol", "reach-avoid", "far-cycle"])
def test_stacked_closing_bounds_are_the_bound_of_each_target(spec: str) -> None:
    """Per node: min(final at its cell where free steps reach the target state, and over the
    landmarks their distance plus the leg), times SAFETY, and at least the straight line."""
    mission = _load(spec)
    abstraction, working, arguments = _inputs(mission, False)
    lazy = lazy_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    allowed = np.repeat(arguments["allowed"], SLOTS)  # type: ignore[call-overload]
    graph = region_graph(lazy, allowed)
    bounds = _Bounds(lazy, graph, 1.0)
    nq, size = lazy.num_states, lazy.num_nodes
    reachable = np.flatnonzero(allowed.repeat(nq))
    rng = np.random.default_rng(3)
    targets = [int(t) for t in rng.choice(reachable, 4)]
    nodes = np.sort(rng.choice(reachable, 200))
    which = rng.integers(0, len(targets), len(nodes))
    stacked = bounds.closings(targets, size)(nodes + which * size)
    for value, node, k in zip(stacked.tolist(), nodes.tolist(), which.tolist(), strict=True):
        target = targets[k]
        to = bounds._to(target)
        assert to.final is not None
        assert to.reach is not None
        cell, q = node // nq, node % nq
        c = int(graph.cell_local[cell])
        expected = float(to.final[cell]) if to.reach[q, c] else float("inf")
        for index in range(len(graph.landmarks)):
            expected = min(expected, float(graph.distance[cell, index] + to.leg[q, c, index]))
        expected *= SAFETY
        (gx, gy), (x, y) = lazy.position[target // nq], lazy.position[cell]
        straight = float(np.sqrt((x - gx) * (x - gx) + (y - gy) * (y - gy)))
        expected = max(expected, straight * (graph.scale * (1.0 - 1e-9)))
        assert value == expected
        # ... and the single target's bound agrees.
        assert float(bounds.closing(target)(np.array([node]))[0]) == expected


@settings(max_examples=200, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0.0, 100.0),
            st.one_of(st.just(float("inf")), st.floats(0.0, 100.0), st.sampled_from([1.0, 2.0])),
        ),
        min_size=1,
        max_size=6,
    ),
    st.sampled_from([0.05, 0.5, 1.0, 3.0]),
)
def test_a_copy_is_limited_by_the_best_of_the_other_copies(
    copies: list[tuple[float, float]], beta: float
) -> None:
    g = np.array([c[0] for c in copies])
    reached = np.array([c[1] for c in copies])
    limit = _others_limit(g, reached, beta)
    totals = g + beta * reached
    for k in range(len(copies)):
        others = [float(totals[j]) for j in range(len(copies)) if j != k]
        if not others:
            assert limit[k] == np.inf
            continue
        allowed = (min(others) - g[k]) / beta
        assert limit[k] >= allowed
        assert limit[k] <= allowed + 1e-8 * (1.0 + abs(allowed))
        # A copy whose lasso ties with or beats every other's keeps its own cycle.
        if np.isfinite(reached[k]) and totals[k] <= min(others):
            assert limit[k] >= reached[k]


def _rooms(beta: float) -> list[str]:
    return [
        _rooms_text(6, [(0, 4), (5, 5), (3, 1), (1, 2), (4, 3)], "patrol", beta),
        _rooms_text(5, [(4, 0), (0, 4), (2, 2), (4, 4)], "cover", beta),
        _rooms_text(7, [(6, 6), (0, 6), (6, 0), (3, 3)], "patrol", beta),
    ]


@pytest.mark.parametrize(
    ("closing_nodes", "lookahead"),
    [(1, 0.0), (1, guided.LOOKAHEAD), (guided.CLOSING_NODES, 0.0), (guided.CLOSING_NODES, 1.0)],
)
@pytest.mark.parametrize("beta", [0.5, 1.0, 2.5])
def test_guided_lasso_costs_the_built_products_however_candidates_are_grouped(
    monkeypatch: pytest.MonkeyPatch, closing_nodes: int, lookahead: float, beta: float
) -> None:
    """One by one or side by side, candidates closed as soon as due or after the prefix
    search went far past them: the same cost as the built product's lasso."""
    monkeypatch.setattr(guided, "CLOSING_NODES", closing_nodes)
    monkeypatch.setattr(guided, "LOOKAHEAD", lookahead)
    for text in _rooms(beta):
        verdict = _costs_agree(load_mission_text(text, "rooms.yaml"), False)
        assert verdict in ("cycle", "stay"), verdict


@pytest.mark.slow
@settings(
    max_examples=max(10, settings().max_examples // 2),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    st.sampled_from(TASKS),
    st.lists(rects, min_size=3, max_size=3),
    st.booleans(),
    st.sampled_from(["length", "hops"]),
    st.sampled_from([0.05, 0.5, 1.0, 3.0, 20.0]),
    st.sampled_from(["right", "closed"]),
    st.sampled_from([(1, 0.0), (guided.CLOSING_NODES, 1.0)]),
)
def test_guided_lasso_costs_the_built_products_one_by_one_or_after_waiting(
    task: str,
    regions: list[tuple[int, int, int, int]],
    hole: bool,
    cost: str,
    beta: float,
    boundary: str,
    grouping: tuple[int, float],
) -> None:
    """Generated missions over the task language, closing searches one at a time as soon as
    due (each incumbent then prunes the prefix search early), or side by side after the
    prefix search went far past the candidates."""
    try:
        mission = load_mission_text(
            _mission_text(task, regions, hole, cost, beta, boundary), "m.yaml"
        )
    except InvalidInputError:
        event("invalid map")
        return
    closing_nodes, lookahead = grouping
    with (
        mock.patch.object(guided, "CLOSING_NODES", closing_nodes),
        mock.patch.object(guided, "LOOKAHEAD", lookahead),
    ):
        event(_costs_agree(mission, False))


@pytest.mark.parametrize("spec", ["example1", "patrol", "far-cycle"])
def test_a_guided_plan_counts_at_least_a_round_per_step_of_its_lasso(spec: str) -> None:
    """A node at k edges from its search's sources is expanded in round k at the earliest:
    the rounds are at least the lasso's steps (the prefix search's to the anchor, the closing
    search's around the cycle; less one each for the sources)."""
    from tlmpc.abstraction import build_abstraction
    from tlmpc.planning.mission import automaton_for
    from tlmpc.planning.plan import plan

    mission = _load(spec)
    abstraction = build_abstraction(mission)
    witness = plan(
        abstraction,
        automaton_for(mission, abstraction),
        formula=mission.formula,
        options=mission.options,
        start_point=mission.robot.start,
        guided=True,
    )
    rounds = witness.stats["search_rounds"]
    assert isinstance(rounds, int)
    cycle = 0 if witness.is_stay else len(witness.cycle)
    assert rounds >= len(witness.prefix) + cycle - 2


@pytest.mark.parametrize("spec", ["example1", "patrol", "reach-avoid", "far-cycle"])
def test_region_minimum_is_the_least_over_each_class_cells(spec: str) -> None:
    """Per local class, by a loop over the cells: the least value over its allowed cells, or
    (entered) over a landmark's boundary entry cells and all of the background's."""
    mission = _load(spec)
    abstraction, working, arguments = _inputs(mission, False)
    lazy = lazy_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    allowed = np.repeat(arguments["allowed"], SLOTS)  # type: ignore[call-overload]
    graph = region_graph(lazy, allowed)
    rng = np.random.default_rng(11)
    values = rng.uniform(0.0, 100.0, lazy.num_cells)
    values[rng.random(lazy.num_cells) < 0.2] = np.inf
    for entered in (False, True):
        expected = [float("inf")] * len(graph.classes)
        for cell, local in enumerate(graph.cell_local.tolist()):
            if local < 0:
                continue
            if entered and local != graph.background and not graph.entry[cell]:
                continue
            expected[local] = min(expected[local], float(values[cell]))
        assert graph.region_minimum(values, entered=entered).tolist() == expected
