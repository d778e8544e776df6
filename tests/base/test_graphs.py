"""The one strongly-connected-components routine against brute-force reachability.

Two nodes share a component iff each reaches the other (a transitive closure computed by a
search from every node); nodes no root reaches get -1; a component's number is smaller than
that of every other component reaching it (the order the automata's post-processing relies on).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.base.graphs import csr, strong_components


def _reach(successors: list[list[int]], start: int) -> set[int]:
    """Nodes reachable from ``start`` by a path of length >= 0."""
    seen = {start}
    todo = [start]
    while todo:
        for nxt in successors[todo.pop()]:
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen


@st.composite
def graphs(draw: Any) -> tuple[list[list[int]], list[int] | None]:
    n = draw(st.integers(1, 14))
    # self-loops and parallel edges included: an automaton has both
    successors = [draw(st.lists(st.integers(0, n - 1), max_size=4)) for _ in range(n)]
    roots = draw(st.none() | st.lists(st.integers(0, n - 1), min_size=1, max_size=3))
    return successors, roots


@given(graphs())
def test_components_are_mutual_reachability_in_reverse_topological_order(
    case: tuple[list[list[int]], list[int] | None],
) -> None:
    successors, roots = case
    n = len(successors)
    label = strong_components(*csr(successors), roots)
    reach = [_reach(successors, u) for u in range(n)]
    reached = set(range(n)) if roots is None else set().union(*(reach[r] for r in roots))
    for u in range(n):
        assert (label[u] >= 0) == (u in reached)
    for u in reached:
        for v in reached:
            mutual = v in reach[u] and u in reach[v]
            assert (label[u] == label[v]) == mutual
            if v in reach[u] and not mutual:
                assert label[u] > label[v]
    assert sorted(set(label) - {-1}) == list(range(len(set(label) - {-1})))


@given(graphs())
def test_numpy_arrays_give_the_same_labels_as_lists(
    case: tuple[list[list[int]], list[int] | None],
) -> None:
    successors, roots = case
    indptr, indices = csr(successors)
    as_arrays = strong_components(
        np.array(indptr, dtype=np.int64), np.array(indices, dtype=np.int64), roots
    )
    assert as_arrays == strong_components(indptr, indices, roots)


def test_a_long_chain_does_not_exhaust_the_stack() -> None:
    n = 200_000
    # 0 -> 1 -> ... -> n-1 -> 0: one component reached through a path n deep
    successors = [[(u + 1) % n] for u in range(n)]
    assert set(strong_components(*csr(successors))) == {0}
    # without the closing edge: n components, the last node's completed first
    successors[-1] = []
    assert strong_components(*csr(successors), [0])[:3] == [n - 1, n - 2, n - 3]
