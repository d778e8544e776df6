"""The abstraction's numpy fast paths agree with the library routines they replace."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from hypothesis import given
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from tlmpc.abstraction.build import _components

IntArray = npt.NDArray[np.int64]


def scipy_components(neighbors: IntArray) -> IntArray:
    """The oracle: scipy's undirected connected components of the same adjacency."""
    count = len(neighbors)
    rows = np.repeat(np.arange(count), neighbors.shape[1])
    cols = neighbors.reshape(-1)
    keep = cols >= 0
    graph = coo_matrix(
        (np.ones(int(keep.sum()), dtype=np.int8), (rows[keep], cols[keep])), shape=(count, count)
    )
    _, labels = connected_components(graph, directed=False)
    return np.asarray(labels, dtype=np.int64)


@st.composite
def adjacencies(draw: st.DrawFn) -> IntArray:
    """n rows of three neighbour slots (-1 = none), not necessarily symmetric."""
    count = draw(st.integers(0, 40))
    slots = st.integers(-1, count - 1) if count else st.just(-1)
    cells = draw(st.lists(slots, min_size=3 * count, max_size=3 * count))
    return np.array(cells, dtype=np.int64).reshape(count, 3)


@given(adjacencies())
def test_components_equal_scipy(neighbors: IntArray) -> None:
    assert _components(neighbors).tolist() == scipy_components(neighbors).tolist()


def test_components_of_a_shuffled_path_and_islands() -> None:
    # A long path numbered at random needs many hooking rounds; isolated triangles and a
    # second path check the numbering by lowest member.
    rng = np.random.default_rng(7)
    count = 5000
    order = rng.permutation(count)
    neighbors = np.full((count, 3), -1, dtype=np.int64)
    path, other = order[:3000], order[3000:4500]  # the rest stay alone
    for chain in (path, other):
        neighbors[chain[:-1], 0] = chain[1:]
        neighbors[chain[1:], 1] = chain[:-1]
    labels = _components(neighbors)
    assert labels.tolist() == scipy_components(neighbors).tolist()
    assert int(labels.max()) + 1 == 2 + (count - 4500)
