"""The guided search's grouping of a round's nodes by copy and by bucket key against a plain
Python grouping: every distinct label once, ascending, with the positions holding it in
their order; and the buckets it fills hold what a dictionary of lists holds."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.planning.guided import GuidedSearch, _Buckets, _runs, _sorted_distinct


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(-3, 6), max_size=30))
def test_runs_group_positions_by_label_in_order(labels: list[int]) -> None:
    expected: dict[int, list[int]] = {}
    for position, label in enumerate(labels):
        expected.setdefault(label, []).append(position)
    found = _runs(np.array(labels, dtype=np.int64))
    assert [label for label, _ in found] == sorted(expected)
    assert all(positions.tolist() == expected[label] for label, positions in found)


@settings(max_examples=100, deadline=None)
@given(st.lists(st.lists(st.tuples(st.integers(0, 50), st.integers(0, 5)), min_size=1), max_size=6))
def test_buckets_hold_each_node_under_its_key(batches: list[list[tuple[int, int]]]) -> None:
    buckets = _Buckets()
    expected: dict[int, list[int]] = {}
    for batch in batches:
        nodes = np.array([node for node, _ in batch], dtype=np.int64)
        keys = np.array([key for _, key in batch], dtype=np.int64)
        buckets.add(nodes, keys)
        for node, key in batch:
            expected.setdefault(key, []).append(node)
    assert sorted(buckets.keys) == sorted(expected)
    for key, held in expected.items():
        assert np.concatenate(buckets.parts[key]).tolist() == held


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(0, 40), max_size=40))
def test_sorted_distinct_is_numpys_unique(values: list[int]) -> None:
    array = np.array(values, dtype=np.int64)
    assert _sorted_distinct(array).tolist() == sorted(set(values))


@settings(max_examples=100, deadline=None)
@given(
    st.integers(1, 4),
    st.lists(st.integers(0, 3), min_size=4, max_size=4),
    st.lists(
        st.tuples(st.integers(0, 99), st.floats(0.0, 20.0)), max_size=30, unique_by=lambda p: p[0]
    ),
)
def test_a_round_of_copies_goes_to_each_copys_buckets(
    copies: int, floors: list[int], queued: list[tuple[int, float]]
) -> None:
    """Searches side by side: node n (copy n // 25) goes to its copy's queue, in the bucket of
    its f raised to that copy's floor, positions in the round's order (a dictionary of lists
    per copy is the oracle)."""
    size = 25
    nodes = np.array([n for n, _ in queued if n // size < copies], dtype=np.int64)
    f = np.array([value for n, value in queued if n // size < copies])
    search = GuidedSearch.__new__(GuidedSearch)
    search.width = 0.5
    search.copy_size = size
    search.queues = [_Buckets() for _ in range(copies)]
    for queue, floor in zip(search.queues, floors, strict=False):
        queue.floor = floor
    search._queue(nodes, f)
    expected: list[dict[int, list[int]]] = [{} for _ in range(copies)]
    for node, value in zip(nodes.tolist(), f.tolist(), strict=True):
        copy = node // size
        key = max(int(value / 0.5), floors[copy])
        expected[copy].setdefault(key, []).append(node)
    for queue, held in zip(search.queues, expected, strict=True):
        assert sorted(queue.keys) == sorted(held)
        assert {key: np.concatenate(parts).tolist() for key, parts in queue.parts.items()} == held
