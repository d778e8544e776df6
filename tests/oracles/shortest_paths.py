"""Shortest paths with clearance, independent of tlmpc: a visibility graph on shapely geometry.

The free space is a shapely polygon (already eroded by the body radius: ``free.buffer(-r)``,
whose round corners are chords inside the true circle's arcs, so the paths found here are never
longer than the true ones and ratios against them are upper bounds).  A shortest path in a
polygonal domain bends only at the domain's vertices, so the graph's nodes are those vertices,
the start, and the points where a path may touch a target region: the corners of the region's
part of the free space and points along its boundary every ``perimeter / SAMPLES``.  Two nodes
are joined when the segment between them lies in the free space (shapely's ``covers`` on a
hair-thin buffer).

"Visit the targets in this order" is a layered graph: a copy of the visibility graph per
number of targets already touched, joined at zero cost where a node lies on (or in) the next
target.  One Dijkstra (scipy) from the start gives the shortest such path; a closed tour
(a patrol's cycle) is the best over every node of the first target of a path from it, through
the other targets, back to itself.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import shapely
import shapely.ops
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

#: Boundary samples per target region (besides its corners).
SAMPLES = 96


def _points_of(geometry: Any) -> list[tuple[float, float]]:
    """Every vertex of a (multi)polygon's rings."""
    points: list[tuple[float, float]] = []
    for polygon in getattr(geometry, "geoms", [geometry]):
        if polygon.is_empty:
            continue
        for ring in [polygon.exterior, *polygon.interiors]:
            points.extend((float(x), float(y)) for x, y in list(ring.coords)[:-1])
    return points


def _samples(target: Any) -> list[tuple[float, float]]:
    points = _points_of(target)
    boundary = target.boundary
    if boundary.length > 0:
        for k in range(SAMPLES):
            p = boundary.interpolate(k / SAMPLES, normalized=True)
            points.append((float(p.x), float(p.y)))
    return points


class VisibilityOracle:
    """Shortest paths in ``free`` that touch ``targets`` (polygons) in order."""

    def __init__(self, free: Any, targets: Sequence[Any], start: tuple[float, float]) -> None:
        self.free = free
        self.targets = [t.intersection(free) for t in targets]
        nodes = [start, *_points_of(free)]
        self.target_nodes: list[list[int]] = []
        for target in self.targets:
            first = len(nodes)
            nodes.extend(_samples(target))
            self.target_nodes.append(list(range(first, len(nodes))))
        self.nodes = np.asarray(nodes, dtype=np.float64)
        count = len(nodes)
        i, j = np.triu_indices(count, k=1)
        lines = shapely.linestrings(
            np.stack([self.nodes[i], self.nodes[j]], axis=1).reshape(-1, 2, 2)
        )
        thin = free.buffer(1e-9)
        seen = shapely.covers(thin, lines)
        seen |= np.all(self.nodes[i] == self.nodes[j], axis=1)
        self.i, self.j = i[seen], j[seen]
        self.lengths = np.hypot(*(self.nodes[self.i] - self.nodes[self.j]).T)
        touches = [shapely.covers(t.buffer(1e-9), shapely.points(self.nodes)) for t in self.targets]
        self.touches = touches
        self._touching_distances: tuple[np.ndarray, np.ndarray] | None = None

    def _layered(self, layers: int, targets: Sequence[int]) -> tuple[Any, int]:
        """The layered graph: layer k -> k + 1 where a node touches ``targets[k]``."""
        count = len(self.nodes)
        rows, cols, vals = [], [], []
        for layer in range(layers):
            shift = layer * count
            rows += [self.i + shift, self.j + shift]
            cols += [self.j + shift, self.i + shift]
            vals += [self.lengths, self.lengths]
        for layer, target in enumerate(targets[: layers - 1]):
            at = np.flatnonzero(self.touches[target])
            rows.append(at + layer * count)
            cols.append(at + (layer + 1) * count)
            vals.append(np.full(len(at), 1e-12))
        size = layers * count
        graph = coo_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), (size, size)
        ).tocsr()
        return graph, count

    def path_length(self, order: Sequence[int] | None = None) -> float:
        """The shortest path from the start touching every target in order (or the targets
        of the indices ``order``, in that order: one visibility graph serves every order)."""
        order = list(range(len(self.targets))) if order is None else list(order)
        k = len(order)
        graph, count = self._layered(k + 1, order)
        dist = dijkstra(graph, indices=0)
        return float(dist[k * count : (k + 1) * count].min())

    def tour_length(self, order: Sequence[int] | None = None) -> float:
        """The shortest closed tour touching every target in cyclic order (start ignored),
        or the targets of the indices ``order``.

        A tour is a cycle of touching nodes, one per target, joined by shortest paths: the
        distances between every two touching nodes are found once (one Dijkstra from each),
        and each order is then a min-plus product of its legs round the cycle."""
        order = list(range(len(self.targets))) if order is None else list(order)
        if len(order) == 1:
            return 0.0
        between, row = self._between_touching()
        sets = [np.flatnonzero(self.touches[t]) for t in order]

        if any(len(nodes) == 0 for nodes in sets):
            return math.inf

        def legs(a: np.ndarray, b: np.ndarray) -> np.ndarray:
            distances: np.ndarray = between[np.ix_(row[a], b)]
            return distances

        best = math.inf
        # a block of first nodes at a time keeps the products' arrays small
        block = max(1, 2_000_000 // max(len(a) * len(b) for a, b in itertools.pairwise(sets)))
        for start in range(0, len(sets[0]), block):
            first = sets[0][start : start + block]
            # reach[s, t]: the shortest path from s (touching the first target) touching each
            # target so far in order, ending at t (touching the latest one)
            reach = legs(first, sets[1])
            for here, there in itertools.pairwise(sets[1:]):
                reach = (reach[:, :, None] + legs(here, there)[None, :, :]).min(axis=1)
            back = legs(sets[-1], first)  # back[t, s]
            best = min(best, float((reach + back.T).min()))
        return best

    def layered_tour_length(self, order: Sequence[int] | None = None) -> float:
        """:meth:`tour_length` by a Dijkstra from every touching node of the first target in
        a layered graph (a second reading of the same definition, slower)."""
        order = list(range(len(self.targets))) if order is None else list(order)
        k = len(order)
        graph, count = self._layered(k, order[1:])
        sources = np.flatnonzero(self.touches[order[0]])
        dist = dijkstra(graph, indices=sources)
        back = dist[np.arange(len(sources)), (k - 1) * count + sources]
        return float(back.min())

    def _between_touching(self) -> tuple[np.ndarray, np.ndarray]:
        """Shortest distances from every node touching some target to every node, and each
        node's row in them (-1 where it touches none)."""
        if self._touching_distances is None:
            touching = np.flatnonzero(np.any(self.touches, axis=0))
            graph, _count = self._layered(1, [])
            row = np.full(len(self.nodes), -1)
            row[touching] = np.arange(len(touching))
            self._touching_distances = (dijkstra(graph, indices=touching), row)
        return self._touching_distances


def geodesic(free: Any, start: tuple[float, float], target: Any) -> float:
    """The shortest path in ``free`` from ``start`` to ``target`` (a point, or a shapely
    geometry such as a segment: its nearest point seen from the path's last corner)."""
    goal = shapely.Point(target) if isinstance(target, tuple) else target
    nodes = np.asarray([start, *_points_of(free)], dtype=np.float64)
    count = len(nodes)
    i, j = np.triu_indices(count, k=1)
    thin = free.buffer(1e-9)
    lines = shapely.linestrings(np.stack([nodes[i], nodes[j]], axis=1).reshape(-1, 2, 2))
    seen = shapely.covers(thin, lines)
    lengths = np.hypot(*(nodes[i[seen]] - nodes[j[seen]]).T)
    graph = coo_matrix(
        (np.concatenate([lengths, lengths]), (np.r_[i[seen], j[seen]], np.r_[j[seen], i[seen]])),
        (count, count),
    ).tocsr()
    dist = dijkstra(graph, indices=0)
    best = math.inf
    for k in range(count):
        if not math.isfinite(dist[k]):
            continue
        here = shapely.Point(nodes[k])
        nearest = shapely.ops.nearest_points(here, goal)[1]
        leg = shapely.LineString([nodes[k], (nearest.x, nearest.y)])
        if leg.length == 0.0 or thin.covers(leg):
            best = min(best, float(dist[k]) + leg.length)
    return best
