"""The guided search: the product expanded on demand, searched under lower bounds.

Three claims, each against an independent computation:

* the lazy product has exactly the built product's edges (weights and marks) out of every node;
* its bounds are lower bounds: never above the exact distances of a Dijkstra search on the
  built product, reversed (scipy's);
* the guided lasso costs what the search on the built product finds, on generated missions
  over the whole task language, both conventions, both metrics, with and without U-turns and
  with ``beta`` on both sides of one; its witness is a real lasso of that cost (the
  brute-force oracle's own cost of the triangle sequence).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Literal

import numpy as np
import pytest
from brute_lasso import lasso_cost
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.degeneralize import degeneralize
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import InvalidInputError, NoPlanError, UsageError
from tlmpc.mission import load_mission, load_mission_text
from tlmpc.mission.model import Mission
from tlmpc.planning.boundary import start_cells, start_point_label
from tlmpc.planning.bounds import region_graph
from tlmpc.planning.explain import invariant_mask
from tlmpc.planning.guided import _Bounds
from tlmpc.planning.lazy import LazyProduct, lazy_product
from tlmpc.planning.mission import automaton_for
from tlmpc.planning.model import Witness
from tlmpc.planning.plan import plan
from tlmpc.planning.product import SLOTS, Product, build_product

ROOT = Path(__file__).resolve().parents[2]

TASKS = (
    "visit a",
    "visit a then b",
    "visit a, b and c",
    "patrol a, b",
    "patrol a, b, c",
    "visit b while avoiding c",
    "stay in b",
    "whenever a, visit b",
    "avoid c until b",
    "visit a then b then return to a",
    "visit a infinitely often",
    "patrol a, b while avoiding c",
)


def _mission_text(
    task: str,
    rects: list[tuple[int, int, int, int]],
    hole: bool,
    cost: str,
    beta: float,
    boundary: str,
) -> str:
    regions = "\n".join(
        f"  {name}: {{rect: [{x0}, {y0}, {x0 + w}, {y0 + h}]}}"
        for name, (x0, y0, w, h) in zip("abc", rects, strict=True)
    )
    holes = "[{rect: [4, 3, 5, 7]}]" if hole else "[]"
    return (
        "version: 1\nworkspace:\n  boundary: {rect: [0, 0, 10, 8]}\n"
        f"  holes: {holes}\nregions:\n{regions}\nrobot: {{start: [0.5, 0.5]}}\n"
        f"task: [{json.dumps(task)}]\n"
        f"options: {{cost: {cost}, beta: {beta}, boundary: {boundary}, min_angle: null}}\n"
    )


def _inputs(mission: Mission, bounces: bool) -> tuple[Abstraction, Automaton, dict[str, object]]:
    abstraction = build_abstraction(mission)
    automaton = automaton_for(mission, abstraction)
    working = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    closed = mission.options.boundary == "closed"
    start = mission.robot.start
    arguments: dict[str, object] = {
        "allowed": invariant_mask(abstraction, mission.formula),
        "start_point": start,
        "metric": mission.options.cost,
        "starts": start_cells(abstraction, start),
        "convention": mission.options.boundary,
        "start_label": start_point_label(abstraction, start) if closed else (),
        "bounces": bounces,
    }
    return abstraction, working, arguments


def _edge_rows(product: Product, lazy: LazyProduct, node: int) -> tuple[list[object], ...]:
    graph = product.graph
    lo, hi = int(graph.indptr[node]), int(graph.indptr[node + 1])
    built = sorted(
        zip(
            graph.targets[lo:hi].tolist(),
            graph.weights[lo:hi].tolist(),
            product.accepting[lo:hi].tolist(),
            strict=True,
        )
    )
    edges = lazy.expand(np.array([node], dtype=np.int64))
    expanded = sorted(
        zip(edges.heads.tolist(), edges.weights.tolist(), edges.accepting.tolist(), strict=True)
    )
    return built, expanded  # type: ignore[return-value]


@pytest.mark.parametrize("spec", ["example1", "patrol", "reach-avoid"])
@pytest.mark.parametrize("boundary", ["right", "closed"])
@pytest.mark.parametrize("bounces", [False, True])
def test_lazy_product_has_the_built_products_edges(
    spec: str, boundary: Literal["right", "closed"], bounces: bool
) -> None:
    mission = load_mission(ROOT / "specs" / f"{spec}.yaml")
    mission = replace(mission, options=replace(mission.options, boundary=boundary))
    abstraction, working, arguments = _inputs(mission, bounces)
    product = build_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    lazy = lazy_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    assert lazy.num_nodes == product.num_nodes
    assert lazy.initial.tolist() == product.initial.tolist()
    every = np.arange(product.num_nodes, dtype=np.int64)
    assert (lazy.stays_accepting(every) == product.stutter_accepting).all()
    edges = lazy.expand(every)
    assert len(edges.heads) == product.graph.nnz
    for node in range(0, product.num_nodes, max(1, product.num_nodes // 400)):
        built, expanded = _edge_rows(product, lazy, node)
        assert built == expanded, node


def _exact_to(product: Product, target: int) -> np.ndarray:
    """Dijkstra (scipy) on the built product reversed: every node's distance to target."""
    graph = product.graph
    matrix = csr_matrix(
        (graph.weights, (graph.targets, graph.sources)),
        shape=(product.num_nodes, product.num_nodes),
    )
    distance: np.ndarray = dijkstra(matrix, indices=target)
    return distance


#: A short cycle far from a landmark the start lies in: the way to the cycle is paid at
#: weight one, the cycle at beta (with beta > 1, charging the way at beta overestimates).
FAR_CYCLE = """\
version: 1
workspace: {boundary: {rect: [0, 0, 10, 4]}}
regions:
  a: {rect: [8.5, 1.5, 9.5, 2.5]}
  b: {rect: [0, 0, 3, 4]}
robot: {start: [0.5, 0.5]}
task: ["visit b", "visit a infinitely often"]
options: {min_angle: null}
"""


def _load(spec: str) -> Mission:
    if spec == "far-cycle":
        return load_mission_text(FAR_CYCLE, "far-cycle.yaml")
    return load_mission(ROOT / "specs" / f"{spec}.yaml")


@pytest.mark.parametrize("spec", ["example1", "patrol", "reach-avoid", "far-cycle"])
@pytest.mark.parametrize("beta", [0.25, 1.0, 4.0])
def test_bounds_never_exceed_the_exact_distances(spec: str, beta: float) -> None:
    _check_bounds(_load(spec), beta)


def _check_bounds(mission: Mission, beta: float) -> None:
    """The closing and lasso bounds at every node against scipy's exact distances on the
    built product (a few closing targets, every accepting edge's tail)."""
    abstraction, working, arguments = _inputs(mission, False)
    product = build_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    lazy = lazy_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    allowed = np.repeat(arguments["allowed"], SLOTS)  # type: ignore[call-overload]
    bounds = _Bounds(lazy, region_graph(lazy, allowed), beta)
    graph = product.graph
    # Targets: the tails of accepting edges (where cycles close), and a spread of others.
    tails = graph.sources[np.flatnonzero(product.accepting)]
    reachable = np.flatnonzero(allowed.repeat(lazy.num_states))
    targets = [*np.unique(tails)[:6].tolist(), *reachable[:: max(1, len(reachable) // 6)]]
    checked = 0
    for target in targets:
        exact = _exact_to(product, int(target))
        nodes = np.flatnonzero(np.isfinite(exact) & allowed.repeat(lazy.num_states))
        bound = bounds.closing(int(target))(nodes)
        assert (bound <= exact[nodes] + 1e-9).all(), target
        checked += len(nodes)
    assert checked > 0
    # The lasso bound is at most the cheapest lasso from every node: the least of its
    # distance to an accepting stay and, over the accepting edges u -> v, of
    # d(x, u) + beta * (w(u, v) + d(v, u)).
    to_go = np.full(product.num_nodes, np.inf)
    stays = np.flatnonzero(product.stutter_accepting)
    if len(stays):
        matrix = csr_matrix(
            (graph.weights, (graph.targets, graph.sources)),
            shape=(product.num_nodes, product.num_nodes),
        )
        to_go = np.minimum(to_go, dijkstra(matrix, indices=stays, min_only=True))
    marked = np.flatnonzero(product.accepting)
    for u in np.unique(graph.sources[marked]).tolist():
        exact = _exact_to(product, u)
        mine = marked[graph.sources[marked] == u]
        around = float((graph.weights[mine] + exact[graph.targets[mine]]).min())
        to_go = np.minimum(to_go, exact + beta * around)
    nodes = np.flatnonzero(np.isfinite(to_go) & allowed.repeat(lazy.num_states))
    if not len(nodes):
        return  # no lasso from anywhere: nothing to bound
    assert (bounds.lasso(nodes) <= to_go[nodes] + 1e-9).all()
    if not len(lazy.initial):
        return
    # The lasso bound at the start is at most the cheapest lasso's cost.
    try:
        witness = plan(
            abstraction,
            automaton_for(mission, abstraction),
            formula=mission.formula,
            options=replace(mission.options, beta=beta),
            start_point=mission.robot.start,
            guided=False,
        )
    except NoPlanError:
        return
    assert float(bounds.lasso(lazy.initial).min()) <= witness.cost + 1e-9


@pytest.mark.slow
@settings(
    max_examples=max(8, settings().max_examples // 4),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    st.sampled_from(TASKS),
    st.lists(
        st.tuples(st.integers(0, 8), st.integers(0, 6), st.integers(1, 4), st.integers(1, 4)),
        min_size=3,
        max_size=3,
    ),
    st.booleans(),
    st.sampled_from(["length", "hops"]),
    st.sampled_from([0.25, 1.0, 4.0]),
    st.sampled_from(["right", "closed"]),
)
@example("patrol a, b", [(2, 2, 4, 4), (6, 2, 1, 4), (0, 6, 1, 1)], False, "length", 1.0, "right")
def test_bounds_never_exceed_the_exact_distances_on_generated_missions(
    task: str,
    regions: list[tuple[int, int, int, int]],
    hole: bool,
    cost: str,
    beta: float,
    boundary: str,
) -> None:
    """Regions large enough that a robot inside one is far from where it was entered: the
    bounds counted from a region's entry cells must hold only right after an entry."""
    try:
        mission = load_mission_text(
            _mission_text(task, regions, hole, cost, beta, boundary), "m.yaml"
        )
    except InvalidInputError:
        event("invalid map")
        return
    _check_bounds(mission, beta)


@pytest.mark.parametrize("spec", ["example1", "patrol", "far-cycle"])
@pytest.mark.parametrize("guided", [False, True])
def test_guided_search_settles_nodes_at_dijkstras_distances(spec: str, guided: bool) -> None:
    """Run to exhaustion (no ceiling), the bucketed search gives every node scipy's Dijkstra
    distance from the initial nodes, with the zero bound and with the lasso bound (a node
    the lasso bound calls hopeless, inf, is never queued)."""
    from tlmpc.planning.guided import GuidedSearch, _Arrays

    mission = _load(spec)
    abstraction, working, arguments = _inputs(mission, False)
    product = build_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    lazy = lazy_product(abstraction, working, **arguments)  # type: ignore[arg-type]
    allowed = np.repeat(arguments["allowed"], SLOTS)  # type: ignore[call-overload]
    graph = product.graph
    matrix = csr_matrix(
        (graph.weights, (graph.sources, graph.targets)),
        shape=(product.num_nodes, product.num_nodes),
    )
    exact = dijkstra(matrix, indices=product.initial, min_only=True)

    def zero(nodes: np.ndarray) -> np.ndarray:
        return np.zeros(len(nodes))

    bound: Callable[[np.ndarray], np.ndarray] = zero
    if guided:
        bound = _Bounds(lazy, region_graph(lazy, allowed), 1.0).lasso
    search = GuidedSearch(lazy, _Arrays.of(lazy.num_nodes), lazy.initial, bound)
    rounds = 0
    while np.isfinite(search.lowest()):
        search.step()
        rounds += 1
    assert rounds > 1
    found = search.arrays.distance(np.arange(lazy.num_nodes))
    hopeless = ~np.isfinite(bound(np.arange(lazy.num_nodes)))
    # Nodes the bound rules out are cut off, and so is whatever is reached only through them.
    check = ~hopeless & np.isfinite(found)
    assert check.sum() > lazy.num_nodes // 20
    assert np.array_equal(found[check], exact[check])
    if not guided:
        assert np.array_equal(np.isfinite(found), np.isfinite(exact))


def _costs_agree(mission: Mission, bounces: bool) -> str:
    abstraction = build_abstraction(mission)
    automaton = automaton_for(mission, abstraction)
    found: list[Witness | None] = []
    for guided in (False, True):
        try:
            found.append(
                plan(
                    abstraction,
                    automaton,
                    formula=mission.formula,
                    options=mission.options,
                    start_point=mission.robot.start,
                    bounces=bounces,
                    guided=guided,
                )
            )
        except NoPlanError:
            found.append(None)
    built, searched = found
    if built is None or searched is None:
        assert (built is None) == (searched is None), "one search finds a plan, the other not"
        return "no plan"
    assert searched.stats["search"] == "guided"
    if not (built.stats["optimal"] and searched.stats["optimal"]):
        return "search cap reached"
    assert searched.cost == pytest.approx(built.cost, rel=1e-9, abs=1e-9)
    if not bounces:  # the oracle walks the no-bounce product
        options = mission.options
        own = lasso_cost(
            abstraction,
            searched.prefix,
            searched.cycle,
            start_point=mission.robot.start,
            metric=options.cost,
            beta=options.beta,
        )
        assert own == pytest.approx(searched.cost, abs=1e-6), "the witness costs its cost"
    return "stay" if searched.is_stay else "cycle"


rects = st.tuples(st.integers(0, 8), st.integers(0, 6), st.integers(1, 3), st.integers(1, 3))


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
    st.booleans(),
)
@example(
    "patrol a, b", [(0, 0, 1, 2), (1, 0, 1, 2), (0, 0, 1, 1)], False, "hops", 3.0, "right", False
)
@example(
    "patrol a, b, c",
    [(0, 0, 2, 2), (6, 4, 2, 2), (7, 0, 2, 2)],
    True,
    "length",
    0.5,
    "closed",
    False,
)
@example(
    "visit a, b and c",
    [(0, 5, 2, 2), (8, 6, 1, 1), (8, 0, 1, 1)],
    True,
    "length",
    1.0,
    "right",
    False,
)
@example(  # a lasso it holds on the way costs more than the optimum, by less than 25 %
    "visit b while avoiding c",
    [(2, 4, 1, 1), (4, 6, 2, 2), (6, 1, 3, 1)],
    True,
    "length",
    0.5,
    "closed",
    False,
)
def test_guided_lasso_costs_what_the_built_product_gives(
    task: str,
    regions: list[tuple[int, int, int, int]],
    hole: bool,
    cost: str,
    beta: float,
    boundary: str,
    bounces: bool,
) -> None:
    text = _mission_text(task, regions, hole, cost, beta, boundary)
    try:
        mission = load_mission_text(text, "m.yaml")
    except InvalidInputError:
        event("invalid map")
        return
    event(_costs_agree(mission, bounces))


def _rooms_text(n: int, rooms: list[tuple[int, int]], task: str, beta: float) -> str:
    """An n x n floor of unit cells, a square room in each chosen cell (the grids the
    guided search is built for, small enough for the built product)."""
    regions = "\n".join(
        f"  r{i}_{j}: {{rect: [{i + 0.25}, {j + 0.25}, {i + 0.75}, {j + 0.75}]}}" for i, j in rooms
    )
    names = [f"r{i}_{j}" for i, j in rooms]
    if task == "patrol":
        tasks = [f"patrol {', '.join(names)}"]
    else:  # cover the others while avoiding the last
        tasks = [f"visit {' and '.join(names[:-1])}", f"avoid {names[-1]}"]
    return (
        f"version: 1\nworkspace: {{boundary: {{rect: [0, 0, {n}, {n}]}}}}\n"
        f"regions:\n{regions}\nrobot: {{start: [0.1, 0.1]}}\n"
        f"task: {json.dumps(tasks)}\n"
        f"options: {{beta: {beta}, min_angle: null, max_area: null}}\n"
    )


@pytest.mark.slow
@settings(
    max_examples=max(6, settings().max_examples // 4),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    st.integers(3, 8).flatmap(
        lambda n: st.tuples(
            st.just(n),
            st.lists(
                st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)),
                min_size=3,
                max_size=6,
                unique=True,
            ),
        )
    ),
    st.sampled_from(["patrol", "cover"]),
    st.sampled_from([0.5, 1.0, 2.5]),
)
def test_guided_lasso_costs_what_the_built_product_gives_on_grids_of_rooms(
    grid: tuple[int, list[tuple[int, int]]], task: str, beta: float
) -> None:
    """Medium missions of the kind the guided search is for: many rooms, a patrol of
    several (long cycles, many candidates) or a cover avoiding one, on a floor of up to
    514 triangles."""
    n, rooms = grid
    mission = load_mission_text(_rooms_text(n, rooms, task, beta), "rooms.yaml")
    event(_costs_agree(mission, False))


@pytest.mark.parametrize("spec", ["example1", "example6", "example7", "patrol", "reach-avoid"])
def test_guided_lasso_on_the_shipped_missions(spec: str) -> None:
    mission = load_mission(ROOT / "specs" / f"{spec}.yaml")
    for beta in (0.3, 1.0, 2.5):
        tuned = replace(mission, options=replace(mission.options, beta=beta))
        assert _costs_agree(tuned, False) != "no plan"


def test_passages_beyond_the_build_budget_are_p060(monkeypatch: pytest.MonkeyPatch) -> None:
    from tlmpc.planning import budget

    monkeypatch.setattr(budget, "MAX_PRODUCT_NODES", 10)
    mission = load_mission(ROOT / "specs" / "example1.yaml")
    abstraction = build_abstraction(mission)
    with pytest.raises(UsageError) as raised:
        plan(
            abstraction,
            automaton_for(mission, abstraction),
            formula=mission.formula,
            options=mission.options,
            start_point=mission.robot.start,
            passages=True,
        )
    assert raised.value.diagnostics[0].code == "P060"


@pytest.mark.parametrize("spec", ["patrol", "example1"])
def test_guided_resume_costs_what_the_built_product_gives(spec: str) -> None:
    """A re-plan under way starts in the start triangle in given automaton states."""
    mission = load_mission(ROOT / "specs" / f"{spec}.yaml")
    abstraction = build_abstraction(mission)
    automaton = automaton_for(mission, abstraction)
    working = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    for state in range(working.num_states):
        costs: list[float | None] = []
        for guided in (False, True):
            try:
                witness = plan(
                    abstraction,
                    automaton,
                    formula=mission.formula,
                    options=mission.options,
                    start_point=mission.robot.start,
                    resume=frozenset({state}),
                    guided=guided,
                )
                costs.append(witness.cost)
            except NoPlanError:
                costs.append(None)
        if costs[0] is None or costs[1] is None:
            assert costs[0] is costs[1]
        else:
            assert costs[1] == pytest.approx(costs[0], rel=1e-9, abs=1e-9)
