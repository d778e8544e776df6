"""Local refinement where a path bends round a corner: rings of smaller triangles about a vertex.

A field that follows a path round a corner can cross its exit edge only a fraction of that
edge away from the corner (the portal insets, and the reach of an affine field heading toward
the wall, both scale with the edge's length), so on a coarse fan of long edges about the corner
the robot swings wide of it.  Cutting every triangle ``(c, a, b)`` about the corner ``c`` at
the fraction ``f`` of its two edges from ``c`` (points ``p_a`` on ``c a``, ``p_b`` on ``c b``)
into the triangle ``(c, p_a, p_b)``, ``t`` shrunk by ``f`` about ``c``, and the trapezoid
``(p_a, a, b, p_b)``, cut along whichever diagonal leaves its thinner piece the fatter, leaves a
fan of edges ``f`` times as long about the corner; rings nest (each cut in the triangles the
cut before left about ``c``).

The mesh stays conforming: an edge through ``c`` is cut at one point shared by the triangles
on both sides, and every edge away from ``c`` is kept whole.  Every piece keeps its
triangle's label and component (it lies inside it).  The first piece of each triangle (the one
about ``c``) keeps its index, the others are appended; the new points are appended to the
vertices.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, triangle_inradius
from tlmpc.abstraction.refine import with_splits
from tlmpc.abstraction.starts import cells_in

#: Each ring keeps this fraction of the edges about the corner: the trapezoids' pieces stay as
#: wide as a triangle whose sides differ by this factor allows (no needle for the fields).
RING_FRACTION = 0.5


def ring_corners(
    abstraction: Abstraction,
    rings: Mapping[int, int],
    start_point: tuple[float, float],
    *,
    fraction: float = RING_FRACTION,
) -> tuple[Abstraction, list[int]]:
    """``abstraction`` with ``rings[c]`` nested rings cut about each corner ``c`` (a mesh
    vertex id; see the module doc), in the mapping's order, and the triangle of
    ``abstraction`` each appended triangle was cut from.

    A corner next to one cut already (sharing an edge with it: their cuts would cross) is
    skipped, and so is one whose triangles hold the start point (the start keeps its
    triangle).  With no corner left, ``abstraction`` itself is returned.
    """
    starts = {
        c.triangle
        for c in cells_in(
            abstraction.vertices,
            abstraction.triangles,
            abstraction.neighbors,
            abstraction.letter_of,
            start_point,
        )
    }
    stars = _stars(abstraction)
    chosen: list[int] = []
    blocked: set[int] = set()
    for corner, count in rings.items():
        star = stars.get(corner, [])
        if count < 1 or not star or corner in blocked or any(t in starts for t in star):
            continue
        chosen.append(corner)
        for t in star:
            blocked.update(abstraction.triangles[t].tolist())
    if not chosen:
        return abstraction, []
    vertices: list[FloatArray] = list(abstraction.vertices)
    tri = list(abstraction.triangles.tolist())
    nbr = list(abstraction.neighbors.tolist())
    letter_of = abstraction.letter_of.tolist()
    component = abstraction.component.tolist()
    pieces = 0
    parents: list[int] = []
    for corner in chosen:
        star = stars[corner]
        for _ in range(rings[corner]):
            _cut_ring(vertices, tri, nbr, letter_of, component, corner, star, fraction)
            parents += [t for t in star for _ in range(2)]
            pieces += 1
    refined = with_splits(
        abstraction,
        np.asarray(vertices, dtype=np.float64).reshape(-1, 2),
        (
            np.asarray(tri, dtype=np.int64).reshape(-1, 3),
            np.asarray(nbr, dtype=np.int64).reshape(-1, 3),
            np.asarray(letter_of, dtype=np.int64),
            np.asarray(component, dtype=np.int64),
        ),
        start_point,
        counter="rings_at_corners",
        count=pieces,
    )
    return refined, parents


def ring_inradius(
    abstraction: Abstraction, corner: int, rings: int, *, fraction: float = RING_FRACTION
) -> float:
    """The smallest inradius of the triangles about ``corner`` once ``rings`` rings are cut
    about it (as :func:`ring_corners` cuts them: the same cut on a copy of its star alone)."""
    star = np.flatnonzero((abstraction.triangles == corner).any(axis=1)).tolist()
    local = {t: k for k, t in enumerate(star)}
    ids = sorted({int(v) for t in star for v in abstraction.triangles[t].tolist()})
    at = {v: k for k, v in enumerate(ids)}
    vertices: list[FloatArray] = [abstraction.vertices[v] for v in ids]
    tri = [[at[int(v)] for v in abstraction.triangles[t].tolist()] for t in star]
    nbr = [[local.get(int(n), -1) for n in abstraction.neighbors[t].tolist()] for t in star]
    letters = [0] * len(star)
    components = [0] * len(star)
    about = list(range(len(star)))
    for _ in range(rings):
        _cut_ring(vertices, tri, nbr, letters, components, at[corner], about, fraction)
    return min(triangle_inradius(np.asarray([vertices[v] for v in corners])) for corners in tri)


def _stars(abstraction: Abstraction) -> dict[int, list[int]]:
    """Each vertex's triangles, in index order."""
    stars: dict[int, list[int]] = {}
    for t, corners in enumerate(abstraction.triangles.tolist()):
        for v in corners:
            stars.setdefault(v, []).append(t)
    return stars


def _cut_ring(
    vertices: list[FloatArray],
    tri: list[list[int]],
    nbr: list[list[int]],
    letter_of: list[int],
    component: list[int],
    c: int,
    star: list[int],
    fraction: float,
) -> None:
    """Cut one ring about vertex ``c`` in its triangles ``star`` (the lists are changed in
    place): each keeps its index for its piece about ``c`` and two pieces are appended, in
    the order of ``star``."""
    point_on: dict[int, int] = {}  # far end w of an edge (c, w) -> the cut point's vertex id
    for t in star:
        for w in tri[t]:
            if w != c and w not in point_on:
                point_on[w] = len(vertices)
                vertices.append(vertices[c] + fraction * (vertices[w] - vertices[c]))
    # Read every triangle's corners and neighbours before any write: (a, b) follow c
    # counter-clockwise, and the triangles across (c, a), (a, b) and (c, b).
    shapes: dict[int, tuple[int, int, int, int, int]] = {}
    for t in star:
        k = tri[t].index(c)
        a, b = tri[t][(k + 1) % 3], tri[t][(k + 2) % 3]
        across_ab, across_cb, across_ca = nbr[t][k], nbr[t][(k + 1) % 3], nbr[t][(k + 2) % 3]
        shapes[t] = (a, b, across_ab, across_cb, across_ca)
    first: dict[int, int] = {}  # t -> its appended pieces: first and first + 1
    for t in star:
        first[t] = len(tri)
        for _ in range(2):
            tri.append([0, 0, 0])
            nbr.append([-1, -1, -1])
            letter_of.append(letter_of[t])
            component.append(component[t])
    # Each trapezoid (p_a, a, b, p_b) is cut along the diagonal whose pieces are the fatter:
    # along p_a b into (p_a, a, b) and (p_a, b, p_b), or along a p_b into (p_a, a, p_b) and
    # (a, b, p_b).  Either way one piece holds the edge (p_a, a) ("a side"), one (b, p_b)
    # ("b side"), one the cut (p_a, p_b) and one the outer edge (a, b).
    along_pa_b = {t: _fatter(vertices, shapes[t][0], shapes[t][1], point_on) for t in star}
    a_side = {t: first[t] for t in star}
    b_side = {t: first[t] + 1 for t in star}
    for t in star:
        a, b, across_ab, across_cb, across_ca = shapes[t]
        p_a, p_b = point_on[a], point_on[b]
        one, two = first[t], first[t] + 1
        from_a = -1 if across_ca < 0 else b_side[across_ca]  # the piece across (p_a, a)
        from_b = -1 if across_cb < 0 else a_side[across_cb]  # the piece across (b, p_b)
        tri[t] = [c, p_a, p_b]
        if along_pa_b[t]:
            # (p_a, a, b): opposite p_a the outer edge, opposite a the diagonal, opposite b
            # the edge (p_a, a); (p_a, b, p_b): opposite p_a the edge (b, p_b), opposite b
            # the cut, opposite p_b the diagonal
            nbr[t] = [two, across_cb, across_ca]
            tri[one], nbr[one] = [p_a, a, b], [across_ab, two, from_a]
            tri[two], nbr[two] = [p_a, b, p_b], [from_b, t, one]
        else:
            # (p_a, a, p_b): opposite p_a the diagonal, opposite a the cut, opposite p_b the
            # edge (p_a, a); (a, b, p_b): opposite a the edge (b, p_b), opposite b the
            # diagonal, opposite p_b the outer edge
            nbr[t] = [one, across_cb, across_ca]
            tri[one], nbr[one] = [p_a, a, p_b], [two, t, from_a]
            tri[two], nbr[two] = [a, b, p_b], [from_b, one, across_ab]
        if across_ab >= 0:
            row = nbr[across_ab]
            row[row.index(t)] = two if not along_pa_b[t] else one


def _fatter(vertices: list[FloatArray], a: int, b: int, point_on: dict[int, int]) -> bool:
    """Whether the trapezoid (p_a, a, b, p_b) of the triangle (c, a, b) is better cut along
    p_a b than along a p_b: its thinner piece is the fatter (height over longest edge)."""
    p_a, p_b = vertices[point_on[a]], vertices[point_on[b]]
    x, y = vertices[a], vertices[b]
    return min(_fatness(p_a, x, y), _fatness(p_a, y, p_b)) >= min(
        _fatness(p_a, x, p_b), _fatness(x, y, p_b)
    )


def _fatness(x: FloatArray, y: FloatArray, z: FloatArray) -> float:
    """A triangle's smallest height over its longest edge."""
    area2 = abs(float((y[0] - x[0]) * (z[1] - x[1]) - (y[1] - x[1]) * (z[0] - x[0])))
    longest = max(float(np.hypot(*(y - x))), float(np.hypot(*(z - y))), float(np.hypot(*(x - z))))
    return area2 / (longest * longest) if longest > 0.0 else 0.0
