"""The region-level bound's inner minimum against its definition, evaluated entry by entry:
``_masked_min(reach, cost)[q, c, l]`` is the least ``cost[l, q']`` over the ``q'`` that
``reach[c, q, q']`` holds (inf when none does or all of those are inf)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.planning.bounds import _masked_min


@st.composite
def cases(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    landmarks = draw(st.integers(0, 4))
    count = draw(st.integers(1, 4))
    nq = draw(st.integers(1, 6))
    reach = np.array(
        draw(st.lists(st.booleans(), min_size=count * nq * nq, max_size=count * nq * nq))
    ).reshape(count, nq, nq)
    value = st.one_of(st.just(math.inf), st.floats(0.0, 1e6, allow_nan=False))
    size = landmarks * nq
    cost = np.array(draw(st.lists(value, min_size=size, max_size=size)), dtype=float)
    return reach, cost.reshape(landmarks, nq)


@settings(max_examples=200, deadline=None)
@given(cases())
def test_masked_min_is_the_least_reached_cost(case: tuple[np.ndarray, np.ndarray]) -> None:
    reach, cost = case
    landmarks, nq = cost.shape
    count = reach.shape[0]
    found = _masked_min(reach, cost)
    assert found.shape == (nq, count, landmarks)
    for q in range(nq):
        for c in range(count):
            for k in range(landmarks):
                expected = min(
                    (float(cost[k, r]) for r in range(nq) if reach[c, q, r]), default=math.inf
                )
                assert found[q, c, k] == expected
