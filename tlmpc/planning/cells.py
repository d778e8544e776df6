"""Convex cells of a mesh and the disturbance their fields reject (beyond a triangle's angles).

A *cell* is a connected group of triangles with one label set and one component whose union
is a convex polygon. The partition is deterministic (Hertel-Mehlhorn style): every edge between
two such triangles is a candidate, sharpest first (the smallest triangle angle at its ends,
then by index), and the two cells across it merge when their union is convex (collinear
corners allowed).

A *cell move* leaves cell C for a neighbour cell C' across their interface I (every mesh edge
the two share: a single segment, as both are convex). Its field is the continuous piecewise
affine interpolation of one velocity u_v per mesh vertex of C, with, at every vertex where
they apply:

* |u_v| <= max_speed;
* m_e·u_v >= d on both endpoints of every side e of C outside I (m_e its inward unit normal);
* xi·u_v >= d (plus a margin) at every vertex of C, for one unit direction xi.

All rows are linear in x on each triangle, so they hold on the whole cell: on a kept side the
closed loop points inward against any push |w| <= d, and xi·x grows at a positive rate, so
the robot leaves the bounded cell, and only through I. Each vertex's rows involve that vertex
alone, so the largest d the rows admit is the smallest *vertex push*: the best
min_k a_k·u over |u| <= 1 for the vertex's normals a_k (the corner push of
:func:`tlmpc.planning.robust.best_direction`, whose direction the control stage's cell field
puts at the vertex), which is cos(s / 2) for unit normals spanning an arc of s < 180 degrees
(the bisector of the arc's ends attains it, and any other direction is farther than s / 2
from one end), and none (0) for normals in no open half-plane.

The direction xi is searched over a fixed fan (FAN directions round the circle from I's mean
outward normal, then a finer fan about the best); the move's *width* (in units of max_speed)
is the smallest vertex push at the best xi found. Where I meets a collinear kept side the
normal of I is infeasible (its two rows are opposite) and a tilted xi is not: hence a search.

A *cell stay* uses the radial law u = kappa (c - x), affine on the whole cell, with
kappa = max_speed / R (R the largest distance from c to a corner): on every side it pushes
inward by kappa times c's distance to the side's line, so its width is r / R (r the smallest
such distance), and under any push of norm d < kappa r the state converges into the disc of
radius d / kappa about c, inside the cell. The centre c is the best r / R a pattern search
finds (:func:`stay_centre`: from the area centroid, a fixed number of halvings and a budget
of moves, so its work is bounded by the cell's sides).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import numpy.typing as npt

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray
from tlmpc.base.memo import Slot, recall
from tlmpc.planning.robust import best_direction, corner_angles

BoolArray = npt.NDArray[np.bool_]
Vector = tuple[float, float]

#: The convex cells' rung's budget, in triangles of the mesh: the partition, each move's rows
#: and each stay's centre search grow with the mesh (the moves' fan searches run over every
#: vertex and direction at once, once per distinct shape). Example 8's meshes (9,250
#: triangles; its reflex cuts' 9,602) fit.
MAX_TRIANGLES = 12_000

#: A corner counts as collinear (180 degrees) when its turn is below this, relative to the
#: product of its two side lengths.
COLLINEAR = 1e-8
#: The stay centre's pattern search halves its step this many times.
CENTRE_HALVINGS = 40
#: The most moves the stay centre's pattern search makes, over all its step sizes: its budget.
#: A search along the axes stalls at a coarse step on a crease of r / R (where two sides, or
#: two corners, tie) and may then climb along the crease at a fine step, one step at a time:
#: up to the cell's size over that step (about 2^CENTRE_HALVINGS) moves, for gains in the
#: last digits. So the search stops moving at this budget (the centre it has reached is
#: sound: its width is r / R there) and evaluates r / R at most
#: :func:`centre_evaluations` times. The searches on the cells of the tests' missions
#: (Example 1's among them) move at most 850 times.
CENTRE_MOVES = 1_024


@dataclass(frozen=True, slots=True)
class Side:
    """One mesh edge on a cell's boundary: from ``start`` to ``end`` (counter-clockwise), the
    triangle holding it, its local index there, and the cell across it (-1: none)."""

    start: int
    end: int
    triangle: int
    edge: int
    neighbour: int


@dataclass(frozen=True, slots=True)
class Cell:
    """A convex union of triangles: its triangles, its boundary (counter-clockwise mesh
    vertices, collinear ones included), its sides (boundary[k] -> boundary[k + 1]) and all
    its mesh vertices (the interior ones too), sorted."""

    index: int
    triangles: tuple[int, ...]
    boundary: tuple[int, ...]
    sides: tuple[Side, ...]
    vertices: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class CellMove:
    """The field family of leaving ``cell`` for ``target``: the flow direction ``xi``, the
    width (the largest disturbance over max_speed its rows admit), and the sides kept."""

    cell: int
    target: int
    xi: Vector
    width: float
    kept: tuple[int, ...]  # indices into the cell's sides
    interface: tuple[int, ...]  # indices into the cell's sides


@dataclass(frozen=True, slots=True)
class CellStay:
    """The radial stay of ``cell``: centre, gain kappa / max_speed and width r / R."""

    cell: int
    centre: Vector
    rate: float  # kappa / max_speed = 1 / R
    width: float


@dataclass(frozen=True)
class Cells:
    """A partition of a mesh's triangles into convex cells."""

    abstraction: Abstraction
    cell_of: IntArray  # (m,)
    cells: tuple[Cell, ...]

    def inward(self, cell: int, side: int) -> Vector:
        """The inward unit normal of a side of ``cell``."""
        s = self.cells[cell].sides[side]
        (ax, ay), (bx, by) = self._point(s.start), self._point(s.end)
        dx, dy = bx - ax, by - ay
        length = math.hypot(dx, dy)
        return (-dy / length, dx / length)

    def _point(self, vertex: int) -> Vector:
        x, y = self.abstraction.vertices[vertex].tolist()
        return (float(x), float(y))

    def vertex_normals(self, move: CellMove) -> dict[int, list[Vector]]:
        """Per mesh vertex of the cell: the inward normals of the kept sides through it."""
        normals: dict[int, list[Vector]] = {v: [] for v in self.cells[move.cell].vertices}
        for k in move.kept:
            side = self.cells[move.cell].sides[k]
            normal = self.inward(move.cell, k)
            normals[side.start].append(normal)
            normals[side.end].append(normal)
        return normals

    def move(self, cell: int, target: int) -> CellMove:
        """The move from ``cell`` to the adjacent ``target`` (width 0 when they share no
        edge or the interface is not one run of sides)."""
        return self._moves.get((cell, target)) or _no_move(cell, target)

    def stay(self, cell: int) -> CellStay:
        """The radial stay of ``cell``."""
        return self._stays[cell]

    @cached_property
    def _moves(self) -> dict[tuple[int, int], CellMove]:
        moves = {}
        pending = []
        for cell in self.cells:
            for target in sorted({s.neighbour for s in cell.sides if s.neighbour >= 0}):
                rows = _pending(self, cell.index, target)
                if rows is None:
                    moves[cell.index, target] = _no_move(cell.index, target)
                else:
                    pending.append(rows)
        for move in _searched_moves(self, pending):
            moves[move.cell, move.target] = move
        return dict(sorted(moves.items()))

    @cached_property
    def _stays(self) -> tuple[CellStay, ...]:
        return tuple(_stay(self, cell.index) for cell in self.cells)


def _no_move(cell: int, target: int) -> CellMove:
    return CellMove(cell=cell, target=target, xi=(1.0, 0.0), width=0.0, kept=(), interface=())


@dataclass(frozen=True, slots=True)
class _Pending:
    """A cell move whose flow direction is still to be searched: the fan's base angle (I's
    mean outward normal) and, per vertex with kept sides through it, their inward normals."""

    cell: int
    target: int
    kept: tuple[int, ...]
    interface: tuple[int, ...]
    base: float
    groups: list[list[Vector]]

    @property
    def shape(self) -> tuple[float, tuple[tuple[float, ...], ...]]:
        """What the search reads: the base angle and each vertex's normals' angles."""
        return (
            self.base,
            tuple(tuple(sorted(math.atan2(y, x) for x, y in n)) for n in self.groups),
        )


def _pending(cells: Cells, cell: int, target: int) -> _Pending | None:
    """The move's rows, or None when it has none (no field leaves by that interface)."""
    sides = cells.cells[cell].sides
    interface = tuple(k for k, s in enumerate(sides) if s.neighbour == target)
    kept = tuple(k for k, s in enumerate(sides) if s.neighbour != target)
    count = len(sides)
    # one run of consecutive sides (cyclically), all on one line: the interface of two convex
    # cells
    runs = sum(1 for k in interface if (k - 1) % count not in interface)
    if runs != 1 or not kept:
        return None
    outward = [(-a, -b) for a, b in (cells.inward(cell, k) for k in interface)]
    nx = sum(a for a, _ in outward) / len(outward)
    ny = sum(b for _, b in outward) / len(outward)
    move = CellMove(cell=cell, target=target, xi=(nx, ny), width=0.0, kept=kept, interface=())
    # The search reads each vertex's normals by their angles alone, and the smallest push
    # over the vertices does not see repeats: one vertex per distinct set of angles.
    distinct: dict[tuple[float, ...], list[Vector]] = {}
    for normals in cells.vertex_normals(move).values():
        if normals:
            distinct.setdefault(tuple(sorted(math.atan2(y, x) for x, y in normals)), normals)
    groups = [distinct[key] for key in sorted(distinct)]
    return _Pending(cell, target, kept, interface, math.atan2(ny, nx), groups)


def _searched_moves(cells: Cells, pending: list[_Pending]) -> list[CellMove]:
    """The moves of ``pending`` with their flow directions: the fan (FAN directions round the
    circle from I's outward normal), then a finer fan about the best of it, every move's
    vertices and directions at once (:func:`_fan_widths`); the width is the smallest vertex
    push at the best direction (the first of equals), each the corner push of
    :func:`~tlmpc.planning.robust.best_direction` (at least 0)."""
    coarse: FloatArray = np.arange(FAN, dtype=np.float64) * (2.0 * math.pi / FAN)
    fine: FloatArray = (np.arange(2 * FINE + 1, dtype=np.float64) - FINE) * (
        2.0 * math.pi / FAN / FINE
    )
    # Moves of the same shape (the same base angle and vertex angles: a map of equal rooms)
    # have the same search: each shape is searched once.
    shapes: dict[tuple[float, tuple[tuple[float, ...], ...]], int] = {}
    unique: list[_Pending] = []
    for move in pending:
        if shapes.setdefault(move.shape, len(unique)) == len(unique):
            unique.append(move)
    bases: FloatArray = np.array([m.base for m in unique], dtype=np.float64)
    best = _best_turns(unique, bases, coarse)
    best = _best_turns(unique, best, fine)
    found = []
    for move, angle in zip(unique, best.tolist(), strict=True):
        xi = (math.cos(angle), math.sin(angle))
        found.append((xi, min(best_direction([*normals, xi])[0] for normals in move.groups)))
    moves = []
    for move in pending:
        xi, width = found[shapes[move.shape]]
        moves.append(
            CellMove(
                cell=move.cell,
                target=move.target,
                xi=xi,
                width=max(width, 0.0),
                kept=move.kept,
                interface=move.interface,
            )
        )
    return moves


#: Vertices whose fan is searched at once (bounds the search's arrays to about
#: FAN x CHUNK floats each).
CHUNK = 4096


def _best_turns(pending: list[_Pending], centres: FloatArray, offsets: FloatArray) -> FloatArray:
    """Per move: the angle among ``centre + offsets`` whose smallest vertex push is largest
    (the first such)."""
    best = np.empty(len(pending), dtype=np.float64)
    start = 0
    while start < len(pending):
        stop, vertices = start, 0
        while stop < len(pending) and (stop == start or vertices < CHUNK):
            vertices += len(pending[stop].groups)
            stop += 1
        turns = centres[start:stop][None, :] + offsets[:, None]  # (directions, moves)
        widths = _fan_widths([m.groups for m in pending[start:stop]], turns)
        best[start:stop] = turns[np.argmax(widths, axis=0), np.arange(stop - start)]
        start = stop
    return best


#: Directions of the fan searched for a cell move's flow direction xi (a full circle), and
#: the finer fan's half count about the best of them (over one step of the first).
FAN = 720
FINE = 50


def _fan_widths(moves: list[list[list[Vector]]], turns: FloatArray) -> FloatArray:
    """(directions, moves): per move and direction angle in ``turns`` (one column per move),
    the smallest vertex push with xi along it (each vertex's kept normals in ``moves``), at
    most 1 and at least 0: the corner push of :func:`~tlmpc.planning.robust.best_direction` of
    the normals and xi, over every vertex and direction at once, from the arc of the angles
    (cos(s / 2) for an arc of s < 180 degrees holding them, else 0; the arc is the circle less
    its widest gap).

    A vertex of a convex cell lies on two of its sides, so it has one or two normals (one is
    repeated: a repeated angle adds a gap of zero). Their angles a0 <= a1 are sorted once; xi's
    angle t falls before a0, between them or after a1, and the circle's gaps are those of
    the sorted three (the same differences as sorting them, with no sort per direction).
    """
    groups = [normals for groups in moves for normals in groups]
    sizes = [len(groups) for groups in moves]
    result = np.ones(turns.shape, dtype=np.float64)
    if not groups:
        return result
    if max(len(normals) for normals in groups) > 2:
        raise ValueError("a vertex of a convex cell lies on at most two of its sides")
    low, high = [], []
    for normals in groups:
        angles = sorted(math.atan2(y, x) % (2.0 * math.pi) for x, y in normals)
        low.append(angles[0])
        high.append(angles[-1])
    a0 = np.array(low, dtype=np.float64)
    a1 = np.array(high, dtype=np.float64)
    full = 2.0 * math.pi
    owner = np.repeat(np.arange(len(moves)), sizes)
    t = np.mod(np.mod(turns, full), full)[:, owner]  # (directions, vertices)
    inner = a1 - a0
    first = np.maximum(np.maximum(a0 - t, inner), t + full - a1)  # t <= a0: [t, a0, a1]
    middle = np.maximum(np.maximum(t - a0, a1 - t), a0 + full - a1)  # a0 < t <= a1
    last = np.maximum(np.maximum(inner, t - a1), a0 + full - t)  # a1 < t: [a0, a1, t]
    widest = np.where(t <= a0, first, np.where(t <= a1, middle, last))
    spread = full - widest
    pushes = np.where(spread < math.pi, np.cos(spread / 2.0), 0.0)
    has = np.flatnonzero(np.asarray(sizes) > 0)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])[has]
    result[:, has] = np.minimum(1.0, np.minimum.reduceat(pushes, starts, axis=1))
    return result


def _stay(cells: Cells, cell: int) -> CellStay:
    polygon = [cells._point(v) for v in cells.cells[cell].boundary]
    found = stay_centre(polygon)
    cx, cy = found.centre
    reach = max(math.hypot(px - cx, py - cy) for px, py in polygon)
    return CellStay(cell=cell, centre=found.centre, rate=1.0 / reach, width=found.width)


@dataclass(frozen=True, slots=True)
class CentreSearch:
    """The centre of a convex polygon's radial stay found by :func:`stay_centre`: the centre,
    its width r / R (at least 0), the search's moves (at most :data:`CENTRE_MOVES`) and its
    evaluations of r / R (at most :func:`centre_evaluations`)."""

    centre: Vector
    width: float
    moves: int
    evaluations: int


def centre_evaluations() -> int:
    """The most evaluations of r / R one :func:`stay_centre` makes: the centroid's, and four
    round each move and round each step size's last position."""
    return 1 + 4 * (CENTRE_MOVES + CENTRE_HALVINGS)


def stay_centre(polygon: list[Vector]) -> CentreSearch:
    """The centre c of the radial stay of the convex ``polygon`` (counter-clockwise), as far
    as a pattern search finds the largest r / R (r: c's smallest distance to a side's line, R:
    its largest to a corner): from the area centroid, along the axes, CENTRE_HALVINGS
    halvings of its step, within :data:`CENTRE_MOVES` moves in all."""
    lines = []
    for k in range(len(polygon)):
        (ax, ay), (bx, by) = polygon[k], polygon[(k + 1) % len(polygon)]
        length = math.hypot(bx - ax, by - ay)
        lines.append(((ay - by) / length, (bx - ax) / length, ax, ay))
    evaluations = 0

    def ratio(x: float, y: float) -> float:
        nonlocal evaluations
        evaluations += 1
        inside = min(nx * (x - ax) + ny * (y - ay) for nx, ny, ax, ay in lines)
        reach = max(math.hypot(px - x, py - y) for px, py in polygon)
        return inside / reach if reach > 0.0 else 0.0

    cx, cy = _centroid(polygon)
    best = ratio(cx, cy)
    step = max(math.hypot(px - cx, py - cy) for px, py in polygon) / 4.0
    moves = 0
    for _ in range(CENTRE_HALVINGS):
        moved = True
        while moved and moves < CENTRE_MOVES:
            moved = False
            for dx, dy in ((step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)):
                value = ratio(cx + dx, cy + dy)
                if value > best:
                    best, cx, cy, moved = value, cx + dx, cy + dy, True
                    moves += 1
                    break
        step /= 2.0
    return CentreSearch(centre=(cx, cy), width=max(best, 0.0), moves=moves, evaluations=evaluations)


def _centroid(polygon: list[Vector]) -> Vector:
    area = sx = sy = 0.0
    x0, y0 = polygon[0]
    for (ax, ay), (bx, by) in zip(polygon, [*polygon[1:], polygon[0]], strict=True):
        cross = (ax - x0) * (by - y0) - (bx - x0) * (ay - y0)
        area += cross
        sx += (ax - x0 + bx - x0) * cross
        sy += (ay - y0 + by - y0) * cross
    if area == 0.0:
        return polygon[0]
    return (x0 + sx / (3.0 * area), y0 + sy / (3.0 * area))


def _turn(a: Vector, b: Vector, c: Vector) -> float:
    """The cross product (b - a) x (c - b) relative to the sides' lengths: > 0 a left turn."""
    ux, uy, vx, vy = b[0] - a[0], b[1] - a[1], c[0] - b[0], c[1] - b[1]
    scale = math.hypot(ux, uy) * math.hypot(vx, vy)
    return (ux * vy - uy * vx) / scale if scale > 0.0 else 0.0


#: The partitions a compilation keeps for reuse (its most recent meshes'): the plan stage asks
#: for the cells of one mesh many times (the planner's mask, the widest-lasso search, the
#: witness check), the control stage again, and each move's search and each stay's centre are
#: computed once per partition.
PARTITIONS: Slot[Cells] = Slot("convex cells", keep=6)


def partition(abstraction: Abstraction) -> Cells:
    """The convex cells of ``abstraction`` (see the module doc); within one compilation the
    same object for the same mesh object while it is among the last ``PARTITIONS.keep``
    partitioned (:mod:`tlmpc.base.memo`), a new partition elsewhere."""
    return recall(PARTITIONS, id(abstraction), abstraction, lambda: _partition(abstraction))


def _partition(abstraction: Abstraction) -> Cells:
    triangles = abstraction.triangles.tolist()
    neighbours = abstraction.neighbors.tolist()
    letter = abstraction.letter_of.tolist()
    component = abstraction.component.tolist()
    points = [(float(x), float(y)) for x, y in abstraction.vertices.tolist()]
    count = len(triangles)
    angles = corner_angles(abstraction).tolist()
    # Every inner edge between triangles of one letter and component, sharpest first: the
    # smallest triangle angle at its ends (merging there widens a corner), then by index.
    candidates = []
    for t in range(count):
        for edge in range(3):
            there = neighbours[t][edge]
            if there <= t or letter[there] != letter[t] or component[there] != component[t]:
                continue
            back = neighbours[there].index(t)
            key = min(
                angles[t][(edge + 1) % 3],
                angles[t][(edge + 2) % 3],
                angles[there][(back + 1) % 3],
                angles[there][(back + 2) % 3],
            )
            candidates.append((key, t, there))
    candidates.sort()
    faces = abstraction.stats.get("cell_faces")
    if faces is not None and len(faces) == count:
        # the convex cells' mesh (tlmpc.abstraction.lines): its faces are the cells, convex
        # and meeting side to side; a merge across two would leave a part of a side between
        # them and the next
        candidates = [c for c in candidates if faces[c[1]] == faces[c[2]]]
    owner = list(range(count))  # union-find over triangles
    boundary: dict[int, list[int]] = {t: list(triangles[t]) for t in range(count)}

    def find(t: int) -> int:
        while owner[t] != t:
            owner[t] = owner[owner[t]]
            t = owner[t]
        return t

    for _, t, there in candidates:
        a, b = find(t), find(there)
        if a == b:
            continue
        union = _merged(boundary[a], boundary[b], points)
        if union is None:
            continue
        low, high = min(a, b), max(a, b)
        owner[high] = low
        boundary[low] = union
        del boundary[high]
    roots = sorted(boundary)
    number = {root: k for k, root in enumerate(roots)}
    cell_of = [number[find(t)] for t in range(count)]
    members: list[list[int]] = [[] for _ in roots]
    for t in range(count):
        members[cell_of[t]].append(t)
    cells = []
    for index, root in enumerate(roots):
        cycle = boundary[root]
        edge_of: dict[tuple[int, int], tuple[int, int]] = {}
        for t in members[index]:
            for edge in range(3):
                a, b = triangles[t][(edge + 1) % 3], triangles[t][(edge + 2) % 3]
                edge_of[a, b] = (t, edge)
        sides = []
        for k, a in enumerate(cycle):
            b = cycle[(k + 1) % len(cycle)]
            t, edge = edge_of[a, b]
            there = neighbours[t][edge]
            sides.append(Side(a, b, t, edge, cell_of[there] if there >= 0 else -1))
        vertices = sorted({v for t in members[index] for v in triangles[t]})
        cells.append(
            Cell(index, tuple(members[index]), tuple(cycle), tuple(sides), tuple(vertices))
        )
    return Cells(
        abstraction=abstraction, cell_of=np.asarray(cell_of, dtype=np.int64), cells=tuple(cells)
    )


def _merged(first: list[int], second: list[int], points: list[Vector]) -> list[int] | None:
    """The boundary of the union of two convex cells sharing one chain of edges, or None when
    that union is not convex. The chain runs counter-clockwise c_0 .. c_k in ``first`` and
    backwards in ``second``; its inner vertices fall inside the union."""
    shared = set(first) & set(second)
    size = len(first)
    # the chain's first vertex in ``first``: shared, its predecessor not
    starts = [i for i in range(size) if first[i] in shared and first[i - 1] not in shared]
    if len(starts) != 1:
        return None
    begin = starts[0]
    run = 0
    while run < size and first[(begin + run) % size] in shared:
        run += 1
    if run < 2 or run != len(shared):
        return None
    c_start, c_end = first[begin], first[(begin + run - 1) % size]
    # ``first`` from c_end round to c_start, then ``second`` from c_start round to c_end
    one = [first[(begin + run - 1 + k) % size] for k in range(size - run + 2)]
    at = second.index(c_start)
    other_size = len(second)
    two = [second[(at + k) % other_size] for k in range(other_size - run + 2)]
    if one[-1] != c_start or two[-1] != c_end:
        return None
    union = one[:-1] + two[:-1]
    for k in range(len(union)):
        a, b, c = (points[union[(k + j) % len(union)]] for j in range(3))
        if _turn(a, b, c) < -COLLINEAR:
            return None
    return union


def cell_realisable(cells: Cells, ratio: float, tolerance: float) -> tuple[BoolArray, BoolArray]:
    """(m, 3) moves and (m,) stays realisable on cells under ``ratio`` x max_speed: a move
    inside one cell always (the cell's field carries the robot on; the labels are the same),
    one into another cell when that cell move's width exceeds the ratio, a stay when its
    cell's stay does (the widths of :func:`cell_widths`)."""
    need = ratio + tolerance
    moves, stays = cell_widths(cells)
    crossing = cells.abstraction.neighbors >= 0
    return np.asarray(crossing & (moves > need), dtype=bool), np.asarray(stays > need, dtype=bool)


def cell_widths(cells: Cells) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """(m, 3) and (m,): per move its width on cells (inf inside one cell: no step of its
    own) and per triangle its cell's stay width."""
    abstraction = cells.abstraction
    here = cells.cell_of
    moves = np.full(abstraction.neighbors.shape, np.inf)
    for t, row in enumerate(abstraction.neighbors.tolist()):
        for i, there in enumerate(row):
            if there >= 0 and here[t] != here[there]:
                moves[t, i] = cells.move(int(here[t]), int(here[there])).width
    stays = np.array([cells.stay(int(c)).width for c in here.tolist()], dtype=np.float64)
    return moves, stays


@dataclass(frozen=True, slots=True)
class CellGroup:
    """Consecutive plan steps inside one cell: its cell, the cell it leaves for (None: the
    robot stays in the cell for good) and the indices of the plan's triangles it covers
    (into prefix + cycle)."""

    cell: int
    target: int | None
    indices: tuple[int, ...]


def cell_groups(
    cells: Cells, prefix: tuple[int, ...], cycle: tuple[int, ...], is_stay: bool
) -> tuple[list[CellGroup], int | None]:
    """The plan ``prefix + cycle^omega`` as cell steps, and the first step of a moving cycle.

    Consecutive triangles of one cell are one step. A cycle inside one cell is a stay of that
    cell (the robot stays in one label set: the same word up to stutter). Where the cycle's
    last and first runs share a cell, the robot coming round is already in the first run's
    cell: the last run is part of the first. A prefix ending in the cycle's first cell hands
    over to the cycle there.
    """
    here = cells.cell_of
    path = [*prefix, *cycle]

    def runs(indices: list[int]) -> list[list[int]]:
        found: list[list[int]] = []
        for i in indices:
            if found and here[path[found[-1][-1]]] == here[path[i]]:
                found[-1].append(i)
            else:
                found.append([i])
        return found

    head = runs(list(range(len(prefix))))
    loop = runs(list(range(len(prefix), len(path))))
    if is_stay or len(loop) == 1:
        # the robot ends in one cell for good: the prefix's runs up to it, then the stay
        last = int(here[path[loop[0][0]]])
        if head and int(here[path[head[-1][0]]]) == last:
            loop[0] = [*head.pop(), *loop[0]]
        groups = [
            CellGroup(int(here[path[r[0]]]), int(here[path[nxt[0]]]), tuple(r))
            for r, nxt in zip(head, [*head[1:], loop[0]][: len(head)], strict=True)
        ]
        indices = [i for r in loop for i in r]
        groups.append(CellGroup(last, None, tuple(indices)))
        return groups, None
    if int(here[path[loop[-1][0]]]) == int(here[path[loop[0][0]]]):
        loop[0] = [*loop[0], *loop.pop()]
    if head and int(here[path[head[-1][0]]]) == int(here[path[loop[0][0]]]):
        loop[0] = [*head.pop(), *loop[0]]
    ordered = [*head, *loop]
    following = [*ordered[1:], loop[0]]
    groups = [
        CellGroup(int(here[path[r[0]]]), int(here[path[nxt[0]]]), tuple(r))
        for r, nxt in zip(ordered, following, strict=True)
    ]
    return groups, len(head)


def group_bounces(groups: list[CellGroup], loop_start: int | None) -> int | None:
    """The first cell step that leaves for the cell it came from (None: none does). Its field
    would push the robot straight back across the interface it entered by."""
    for k, group in enumerate(groups):
        if group.target is None:
            continue
        entries = [groups[k - 1].cell] if k > 0 else []
        if loop_start is not None and k == loop_start:
            entries.append(groups[-1].cell)
        if group.target in entries:
            return k
    return None


def witness_on_cells(
    cells: Cells,
    prefix: tuple[int, ...],
    cycle: tuple[int, ...],
    is_stay: bool,
    ratio: float,
    tolerance: float,
) -> bool:
    """True when every cell step of the plan rejects ``ratio`` x max_speed (with
    ``tolerance``) and none leaves for the cell it came from."""
    groups, loop_start = cell_groups(cells, prefix, cycle, is_stay)
    if group_bounces(groups, loop_start) is not None:
        return False
    need = ratio + tolerance
    for group in groups:
        if group.target is None:
            width = cells.stay(group.cell).width
        else:
            width = cells.move(group.cell, group.target).width
        if not width > need:
            return False
    return True
