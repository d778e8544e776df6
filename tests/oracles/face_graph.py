"""Independent oracle: does any continuous trajectory satisfy a Next-free task on a map?

Definition (docs/semantics.md, "Completeness"): cut the free space by every region boundary
into faces (shapely ``polygonize`` of the noded linework); the robot can stay in a face,
cross into any face that shares a boundary piece of positive length with it, or pass through
a *point contact*: a vertex of the arrangement that two faces' closures share (faces that
touch only there included).  A trajectory satisfying the task exists iff this face graph
(with self-loops) times the task's Büchi automaton has a reachable accepting cycle.  The
automaton comes from Spot, never from tlmpc; neither the triangulation nor tlmpc's product
is used here.

Under the right-continuous convention a boundary instant reads the face entered, so a point
contact is one more adjacency.  Under the closed convention (:func:`satisfiable_closed`) the
run is a word of *instants*: a boundary point (its closed label: every region within a
rounding distance), then for each open piece an instant "just after" its start (marked
``J``) and a "later" one, as in tests/oracles/continuous_ltl.py.  There an ``a U b`` witness
may be a "just after" instant only at the very instant of evaluation, which discrete LTL over
the instants says as ``b | (a U (b & !J))`` (its dual for R); Spot then decides the rewritten
task on the instant graph.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import shapely
from shapely.geometry import Point, Polygon
from shapely.ops import polygonize, unary_union

from tlmpc.ltl.ast import Formula

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
    #: Point contacts: (closed label of the point, faces whose closure holds it).
    contacts: tuple[tuple[frozenset[str], tuple[int, ...]], ...] = ()
    #: The start point's closed label.
    start_label: frozenset[str] = frozenset()
    #: Adjacency through boundary pieces of positive length only (``adjacent`` adds the
    #: point contacts).
    edge_adjacent: tuple[frozenset[int], ...] = ()


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
    extent = max(free.bounds[2] - free.bounds[0], free.bounds[3] - free.bounds[1])
    near = 1e-9 * extent
    edge_adjacent = tuple(frozenset(near) for near in adjacent)
    contacts: list[tuple[frozenset[str], tuple[int, ...]]] = []
    corners = sorted(
        {
            (round(x, 9), round(y, 9))
            for face in faces
            for ring in (face.exterior, *face.interiors)
            for x, y in ring.coords
        }
    )
    for x, y in corners:
        probe = Point(x, y)
        touching = tuple(
            j for j in tree.query(probe.buffer(near)).tolist() if faces[j].distance(probe) <= near
        )
        if touching:
            label = frozenset(n for n, s in shapes.items() if s.distance(probe) <= near)
            contacts.append((label, touching))
            for i in touching:
                adjacent[i].update(j for j in touching if j != i)
    point = Point(start)
    start_label = frozenset(n for n, s in shapes.items() if s.distance(point) <= near)
    starts = [i for i, f in enumerate(faces) if f.contains(point)]
    if not starts and on_boundary:
        # A start on a boundary can move into any face whose closure holds it (under the
        # right-continuous convention its first label is that face's).
        starts = [i for i, f in enumerate(faces) if f.intersects(point)]
    if len(starts) != 1 and not (on_boundary and starts):
        raise ValueError("the start must lie strictly inside one face")
    return FaceGraph(
        faces=faces,
        labels=labels,
        adjacent=adjacent,
        start=starts[0],
        starts=tuple(starts),
        contacts=tuple(contacts),
        start_label=start_label,
        edge_adjacent=edge_adjacent,
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


JUST_AFTER = "J"


def closed_rewrite(formula: Formula) -> str:
    """``formula`` (NNF-free input) in Spot syntax over instants, under the closed convention:
    ``a U b`` becomes ``b | (a U (b & !J))`` and ``a R b`` becomes ``b & (a R (b | J))``
    (see the module doc); F, G, W, M and the Boolean connectives by their definitions."""
    return _rewrite(formula)


def _rewrite(f: Formula) -> str:
    from tlmpc.ltl import ast

    if isinstance(f, ast.Const):
        return "1" if f.value else "0"
    if isinstance(f, ast.Prop):
        return f.name
    if isinstance(f, ast.Not):
        return f"!({_rewrite(f.arg)})"
    if isinstance(f, ast.And):
        return "(" + " & ".join(_rewrite(a) for a in f.args) + ")"
    if isinstance(f, ast.Or):
        return "(" + " | ".join(_rewrite(a) for a in f.args) + ")"
    if isinstance(f, ast.Implies):
        return f"(!({_rewrite(f.left)}) | {_rewrite(f.right)})"
    if isinstance(f, ast.Equiv):
        a, b = _rewrite(f.left), _rewrite(f.right)
        return f"(({a} & {b}) | (!({a}) & !({b})))"
    if isinstance(f, ast.Until):
        a, b = _rewrite(f.left), _rewrite(f.right)
        return f"({b} | ({a} U ({b} & !{JUST_AFTER})))"
    if isinstance(f, ast.Release):
        a, b = _rewrite(f.left), _rewrite(f.right)
        return f"({b} & ({a} R ({b} | {JUST_AFTER})))"
    if isinstance(f, ast.Eventually):
        return _rewrite(ast.Until(ast.Const(True), f.arg))
    if isinstance(f, ast.Globally):
        return _rewrite(ast.Release(ast.Const(False), f.arg))
    if isinstance(f, ast.WeakUntil):
        return f"({_rewrite(ast.Until(f.left, f.right))} | {_rewrite(ast.Globally(f.left))})"
    if isinstance(f, ast.StrongRelease):
        return _rewrite(ast.Until(f.right, ast.And((f.left, f.right))))
    raise TypeError(f"not a Next-free LTL node: {f!r}")


def satisfiable_closed(graph: FaceGraph, formula: Formula) -> bool:
    """True iff some trajectory satisfies ``formula`` under the closed convention.

    Nodes of the instant graph: ``("pt", letter, face)`` a boundary point about to enter
    ``face``; ``("ja", face)`` and ``("lt", face)`` the two instants of an open piece.  From a
    "later" instant the robot stays, or reaches a point: inside its face (its own label),
    on an edge shared with a face (both labels), or at a point contact (that point's label)
    from which it enters any face touching it.
    """
    spot_formula = closed_rewrite(formula)
    Node = tuple[object, ...]
    labels: dict[Node, frozenset[str]] = {}
    succ_nodes: dict[Node, list[Node]] = {}

    def add(node: Node, label: frozenset[str], targets: list[Node]) -> None:
        labels[node] = label
        succ_nodes[node] = targets

    leaving: list[list[tuple[frozenset[str], int]]] = [[] for _ in graph.faces]
    for face in range(len(graph.faces)):
        leaving[face].append((graph.labels[face], face))
    for label, touching in graph.contacts:
        for i in touching:
            leaving[i].extend((label, j) for j in touching)
    for face, near in enumerate(graph.edge_adjacent):
        for other in near:
            leaving[face].append((graph.labels[face] | graph.labels[other], other))
    for face in range(len(graph.faces)):
        add(("ja", face), graph.labels[face] | {JUST_AFTER}, [("lt", face)])
        points = [("pt", label, target) for label, target in dict.fromkeys(leaving[face])]
        add(("lt", face), graph.labels[face], [("lt", face), *points])
        for _, label, target in points:
            add(("pt", label, target), label, [("ja", target)])
    roots: list[Node] = []
    for start in graph.starts or (graph.start,):
        node = ("pt", graph.start_label, start)
        add(node, graph.start_label, [("ja", start)])
        roots.append(node)
    return _accepting_lasso(spot_formula, labels, succ_nodes, roots)


def _accepting_lasso(
    ltl: str,
    labels: Mapping[tuple[object, ...], frozenset[str]],
    succ_nodes: Mapping[tuple[object, ...], list[tuple[object, ...]]],
    roots: list[tuple[object, ...]],
) -> bool:
    """Whether the labelled graph (a run reads each node's label) has a run from a root
    that Spot's Büchi automaton of ``ltl`` accepts."""
    automaton = spot.translate(ltl, "BA")
    edges = [
        (e.src, e.dst, e.cond, bool(e.acc.count()))
        for s in range(automaton.num_states())
        for e in automaton.out(s)
    ]
    init = automaton.get_init_state_number()
    test = _letter_test(automaton)
    cache: dict[tuple[int, frozenset[str]], bool] = {}

    def allows(index: int, label: frozenset[str]) -> bool:
        key = (index, label)
        if key not in cache:
            cache[key] = test(edges[index][2], label)
        return cache[key]

    Product = tuple[tuple[object, ...], int]
    start_nodes: list[Product] = [
        (root, dst)
        for root in roots
        for index, (src, dst, _, _) in enumerate(edges)
        if src == init and allows(index, labels[root])
    ]
    succ: dict[Product, list[tuple[Product, bool]]] = {}
    stack = list(dict.fromkeys(start_nodes))
    seen = set(stack)
    while stack:
        node, state = stack.pop()
        found: list[tuple[Product, bool]] = []
        for target in succ_nodes[node]:
            for index, (src, dst, _, acc) in enumerate(edges):
                if src == state and allows(index, labels[target]):
                    found.append(((target, dst), acc))
        succ[(node, state)] = found
        for nxt, _ in found:
            if nxt not in seen:
                seen.add(nxt)
                stack.append(nxt)
    for u, outs in succ.items():
        for v, acc in outs:
            if acc and _reaches(succ, v, u):  # type: ignore[arg-type]
                return True
    return False
