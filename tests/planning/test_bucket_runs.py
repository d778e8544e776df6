"""The guided search's grouping of a round's nodes by copy and by bucket key against a plain
Python grouping: every distinct label once, ascending, with the positions holding it in
their order; and the buckets it fills hold what a dictionary of lists holds."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.planning.guided import _Buckets, _runs


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
