"""Independent oracle: does any continuous trajectory satisfy a Next-free task on a map?

Definition (docs/semantics.md, "Completeness"): cut the free space by every region boundary
into faces (shapely ``polygonize`` of the noded linework); the robot can stay in a face or
cross into any face that shares a boundary piece of positive length with it.  A trajectory
satisfying the task exists iff this face graph (with self-loops) times the task's Büchi
automaton has a reachable accepting cycle.  The automaton comes from Spot, never from tlmpc;
neither the triangulation nor tlmpc's product is used here.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import shapely
from shapely.geometry import Point, Polygon
from shapely.ops import polygonize, unary_union

with warnings.catch_warnings():
    # Spot's SWIG bindings warn on import; the suite turns warnings into errors.
    warnings.simplefilter("ignore")
    import spot

Coords = Sequence[tuple[float, float]]


@dataclass(frozen=True)
class FaceGraph:
    """Faces (shapely polygons), their label sets, adjacency, and the start face."""

    faces: list[Polygon]
    labels: list[frozenset[str]]
    adjacent: list[set[int]]
    start: int
    #: Every face whose closure holds the start (one face unless the start is on a boundary).
    starts: tuple[int, ...] = ()


def face_graph(
    boundary: Coords,
    holes: Sequence[Coords],
    regions: Mapping[str, Coords],
    start: tuple[float, float],
    *,
    on_boundary: bool = False,
) -> FaceGraph:
    """The face graph of the free space cut by every region boundary.

    With ``on_boundary``, a start on face boundaries is allowed: it may begin in any face
    whose closure holds it.
    """
    free = Polygon(boundary)
    for hole in holes:
        free = free.difference(Polygon(hole))
    shapes = {name: Polygon(points) for name, points in regions.items()}
    lines = unary_union([free.boundary, *(s.boundary for s in shapes.values())])
    faces = [f for f in polygonize(lines) if f.area > 0 and free.contains(f.representative_point())]
    labels = []
    for face in faces:
        inside = face.representative_point()
        labels.append(frozenset(n for n, s in shapes.items() if s.contains(inside)))
    adjacent: list[set[int]] = [set() for _ in faces]
    tree = shapely.STRtree(faces)
    for i, face in enumerate(faces):
        for j in tree.query(face).tolist():
            if j <= i:
                continue
            shared = face.boundary.intersection(faces[j].boundary)
            if shared.length > 1e-9:
                adjacent[i].add(j)
                adjacent[j].add(i)
    point = Point(start)
    starts = [i for i, f in enumerate(faces) if f.contains(point)]
    if not starts and on_boundary:
        # A start on a boundary can move into any face whose closure holds it (under the
        # right-continuous convention its first label is that face's).
        starts = [i for i, f in enumerate(faces) if f.intersects(point)]
    if len(starts) != 1 and not (on_boundary and starts):
        raise ValueError("the start must lie strictly inside one face")
    return FaceGraph(
        faces=faces, labels=labels, adjacent=adjacent, start=starts[0], starts=tuple(starts)
    )


def _letter_test(automaton: spot.twa_graph) -> Callable[[object, frozenset[str]], bool]:
    """``test(cond, letter)``: does the edge condition ``cond`` accept the letter?"""
    d = automaton.get_dict()
    false = spot.formula_to_bdd(spot.formula.ff(), d, automaton)
    names = [ap.ap_name() for ap in automaton.ap()]

    def test(cond: object, letter: frozenset[str]) -> bool:
        literals = [
            spot.formula.ap(n) if n in letter else spot.formula.Not(spot.formula.ap(n))
            for n in names
        ]
        cube = spot.formula_to_bdd(spot.formula.And(literals), d, automaton)
        return bool((cond & cube) != false)

    return test


def satisfiable_on(graph: FaceGraph, ltl: str) -> bool:
    """True iff some run of the face graph (stays allowed) satisfies ``ltl`` (Spot syntax)."""
    automaton = spot.translate(ltl, "BA")
    edges = [
        (e.src, e.dst, e.cond, bool(e.acc.count()))
        for s in range(automaton.num_states())
        for e in automaton.out(s)
    ]
    init = automaton.get_init_state_number()
    test = _letter_test(automaton)
    accepts = {
        (index, face): test(cond, graph.labels[face])
        for index, (_, _, cond, _) in enumerate(edges)
        for face in range(len(graph.faces))
    }

    def successors(face: int, state: int) -> list[tuple[tuple[int, int], bool]]:
        found = []
        for target in (face, *graph.adjacent[face]):
            for index, (src, dst, _, acc) in enumerate(edges):
                if src == state and accepts[index, target]:
                    found.append(((target, dst), acc))
        return found

    # Nodes (face, automaton state after reading that face's letter).
    roots = [
        (start, dst)
        for start in graph.starts or (graph.start,)
        for index, (src, dst, _, _) in enumerate(edges)
        if src == init and accepts[index, start]
    ]
    succ: dict[tuple[int, int], list[tuple[tuple[int, int], bool]]] = {}
    stack = list(dict.fromkeys(roots))
    seen = set(stack)
    while stack:
        node = stack.pop()
        succ[node] = successors(*node)
        for nxt, _ in succ[node]:
            if nxt not in seen:
                seen.add(nxt)
                stack.append(nxt)
    # An accepting lasso exists iff some reachable accepting edge u -> v closes: u reachable
    # from v.
    for u, outs in succ.items():
        for v, acc in outs:
            if acc and _reaches(succ, v, u):
                return True
    return False


def _reaches(
    succ: Mapping[tuple[int, int], list[tuple[tuple[int, int], bool]]],
    source: tuple[int, int],
    target: tuple[int, int],
) -> bool:
    stack, seen = [source], {source}
    while stack:
        node = stack.pop()
        if node == target:
            return True
        for nxt, _ in succ[node]:
            if nxt not in seen:
                seen.add(nxt)
                stack.append(nxt)
    return False
