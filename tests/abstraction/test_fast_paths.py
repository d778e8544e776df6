"""The abstraction's numpy fast paths agree with the library routines they replace."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components as scipy_connected_components
from shapely.geometry import MultiPolygon, Point, Polygon

from tlmpc.abstraction.build import _labels, _min_angle, connected_components
from tlmpc.abstraction.triangulate import _polygons, _rings, _rings_of_all, _unique_rows
from tlmpc.ltl.ast import TRUE
from tlmpc.mission.model import Mission, Region, Robot, Workspace

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
    _, labels = scipy_connected_components(graph, directed=False)
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
    assert connected_components(neighbors).tolist() == scipy_components(neighbors).tolist()


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
    labels = connected_components(neighbors)
    assert labels.tolist() == scipy_components(neighbors).tolist()
    assert int(labels.max()) + 1 == 2 + (count - 4500)


@given(
    st.lists(st.tuples(st.integers(-(2**40), 2**40), st.integers(-3, 3)), min_size=0, max_size=60),
    st.booleans(),
)
def test_unique_rows_equal_numpy_unique(pairs: list[tuple[int, int]], huge: bool) -> None:
    rows = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    if huge and len(rows):  # spans too wide to pack: the record sort is used
        rows[:, 1] = rows[:, 1] * 2**40
    first, inverse = _unique_rows(rows)
    if len(rows) == 0:
        assert len(first) == len(inverse) == 0
        return
    _, want_first, want_inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    assert first.tolist() == want_first.tolist()
    assert inverse.tolist() == want_inverse.reshape(-1).tolist()


def test_rings_of_all_equal_the_part_by_part_rings() -> None:
    square = Polygon([(0, 0), (4, 0), (4, 4), (0, 4)])
    holed = Polygon([(0, 0), (9, 0), (9, 9), (0, 9)], [[(1, 1), (2, 1), (2, 2)]])
    multi = MultiPolygon([square, Polygon([(5, 5), (6, 5), (6, 6)])])
    empty = Polygon()
    for shapes in ([square, square], [square, holed, multi, empty, square], [empty], []):
        want = [ring for shape in shapes for part in _polygons(shape) for ring in _rings(part)]
        got = _rings_of_all(shapes)
        assert [shapely.to_wkb(r) for r in got] == [shapely.to_wkb(r) for r in want]


@st.composite
def overlapping_regions(draw: st.DrawFn) -> list[Polygon]:
    shapes = []
    for _ in range(draw(st.integers(0, 6))):
        x0 = draw(st.integers(0, 8))
        y0 = draw(st.integers(0, 8))
        w = draw(st.integers(1, 4))
        h = draw(st.integers(1, 4))
        if draw(st.booleans()):
            shapes.append(Polygon([(x0, y0), (x0 + w, y0), (x0 + w, y0 + h), (x0, y0 + h)]))
        else:
            shapes.append(Polygon([(x0, y0), (x0 + w, y0 + h / 2), (x0 + w / 2, y0 + h)]))
    return shapes


@settings(deadline=None)
@given(overlapping_regions(), st.integers(0, 2**32 - 1))
def test_labels_equal_a_per_triangle_shapely_test(shapes: list[Polygon], seed: int) -> None:
    # Triangles anywhere (the fast path does not rely on the mesh): letters are the sets of
    # regions whose shape has the centroid strictly inside.
    rng = np.random.default_rng(seed)
    vertices = rng.integers(-1, 12, size=(30, 2)).astype(np.float64) + rng.random((30, 2))
    triangles = rng.integers(0, 30, size=(50, 3)).astype(np.int64)
    names = [f"r{k}" if k % 2 else f"a{k}" for k in range(len(shapes))]
    mission = Mission(
        name="t",
        workspace=Workspace(boundary=((0.0, 0.0), (12.0, 0.0), (12.0, 12.0), (0.0, 12.0))),
        regions=tuple(
            Region(name=n, polygon=tuple(shape.exterior.coords[:-1]))
            for n, shape in zip(names, shapes, strict=True)
        ),
        robot=Robot(start=(0.5, 0.5)),
        formula=TRUE,
    )
    letter_of, letters = _labels(mission, vertices, triangles, list(shapes))
    centroids = vertices[triangles].mean(axis=1)
    want = [
        tuple(sorted(n for n, shape in zip(names, shapes, strict=True) if Point(c).within(shape)))
        for c in centroids.tolist()
    ]
    assert letters == tuple(sorted({(), *want}, key=lambda k: (len(k), k)))
    assert [letters[i] for i in letter_of.tolist()] == want


def _reference_min_angle(corners: npt.NDArray[np.float64]) -> list[float]:
    """Each triangle's smallest angle, corner by corner with the law of cosines' terms."""
    out = []
    for triangle in corners.tolist():
        angles = []
        for k in range(3):
            p, q, r = triangle[k], triangle[(k + 1) % 3], triangle[(k + 2) % 3]
            u = (q[0] - p[0], q[1] - p[1])
            v = (r[0] - p[0], r[1] - p[1])
            cos = (u[0] * v[0] + u[1] * v[1]) / (np.hypot(*u) * np.hypot(*v))
            angles.append(float(np.degrees(np.arccos(min(1.0, max(-1.0, cos))))))
        out.append(min(angles))
    return out


@given(st.integers(0, 2**32 - 1))
def test_min_angle_is_the_smallest_corner_angle(seed: int) -> None:
    rng = np.random.default_rng(seed)
    corners = rng.random((40, 3, 2)) * 10.0
    got = _min_angle(corners).tolist()
    want = _reference_min_angle(corners)
    assert np.allclose(got, want, rtol=1e-9, atol=1e-9)


@st.composite
def _meshes_in_pieces(draw: st.DrawFn) -> tuple[IntArray, IntArray]:
    """Triangles over a few shared vertices, each in a drawn component (numbered from 0)."""
    count = draw(st.integers(1, 30))
    vertices = draw(st.integers(3, 40))
    triangles = np.array(
        draw(
            st.lists(
                st.lists(st.integers(0, vertices - 1), min_size=3, max_size=3),
                min_size=count,
                max_size=count,
            )
        ),
        dtype=np.int64,
    )
    pieces = draw(st.lists(st.integers(0, 6), min_size=count, max_size=count))
    _, component = np.unique(np.array(pieces), return_inverse=True)
    return triangles, component.reshape(-1).astype(np.int64)


@given(_meshes_in_pieces())
def test_touching_components_join_the_pieces_that_share_a_vertex(
    mesh: tuple[IntArray, IntArray],
) -> None:
    from tlmpc.abstraction.build import _touching_components
    from tlmpc.abstraction.model import Abstraction

    triangles, component = mesh
    abstraction = Abstraction(
        vertices=np.zeros((int(triangles.max()) + 1, 2)),
        triangles=triangles,
        neighbors=np.full(triangles.shape, -1, dtype=np.int64),
        letter_of=np.zeros(len(triangles), dtype=np.int64),
        letters=((),),
        start=0,
        component=component,
        regions={},
    )
    # The definition, pair by pair: two triangles of one component, or with a common vertex,
    # are in one group; a group is named by its lowest component.
    group = component.tolist()
    changed = True
    while changed:
        changed = False
        for a in range(len(triangles)):
            for b in range(len(triangles)):
                touch = set(triangles[a].tolist()) & set(triangles[b].tolist())
                if touch or component[a] == component[b]:
                    low = min(group[a], group[b])
                    if group[a] != low or group[b] != low:
                        group[a] = group[b] = low
                        changed = True
    assert _touching_components(abstraction).tolist() == group


@given(st.integers(0, 2**32 - 1), st.integers(0, 50))
def test_centroids_are_the_mean_of_the_corners_bit_for_bit(seed: int, count: int) -> None:
    from tlmpc.abstraction.build import _centroids

    rng = np.random.default_rng(seed)
    vertices = rng.normal(size=(max(count, 1), 2)) * 10.0 ** rng.integers(-8, 9)
    triangles = rng.integers(0, len(vertices), size=(count, 3))
    expected = vertices[triangles].mean(axis=1) if count else np.zeros((0, 2))
    assert _centroids(vertices, triangles).tobytes() == expected.tobytes()
