"""An independent shortest-time oracle: how soon can a robot at speed ``v`` reach a region?

A different formulation from tlmpc's (which searches a triangulation's reflex corners and the
goal's edge feet): the free space is built from the mission's polygons with shapely (the
closure of the workspace minus the holes and the avoided regions), and a visibility graph
joins the start, *every* corner of the free space and points spaced at most ``spacing`` apart
along the goal's boundary; scipy's Dijkstra gives the shortest path to the nearest of those
points.  That path is achievable (an upper bound), and the true shortest path is at most
``spacing / 2`` shorter (it ends on the goal's boundary, within ``spacing / 2`` of a point the
graph has, and the boundary between them lies in the goal), so ``[upper - spacing/2, upper]``
holds the true length.  Sequences "a, then b" are searched from every point placed on a's
boundary (each point's distance from the start plus its distance to b), to ``spacing``.

Imports nothing from tlmpc.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

Polygon = Sequence[Sequence[float]]


@dataclass(frozen=True)
class Interval:
    """The true shortest length lies in ``[lower, upper]``."""

    lower: float
    upper: float


def free_space(
    boundary: Polygon, holes: Sequence[Polygon], avoid: Sequence[Polygon]
) -> shapely.Geometry:
    """The closed set the robot may occupy."""
    space = shapely.Polygon(boundary)
    for hole in holes:
        space = space.difference(shapely.Polygon(hole))
    for region in avoid:
        # the robot may come arbitrarily close to an avoided region, so path lengths are
        # measured in the closure of what is left (shapely's difference is that closure); a
        # stretch along the region's boundary is in the region, never free
        space = space.difference(shapely.Polygon(region))
    return space


def _corners(space: shapely.Geometry) -> list[tuple[float, float]]:
    found: list[tuple[float, float]] = []
    for part in shapely.get_parts(space):
        if isinstance(part, shapely.Polygon):
            for ring in [part.exterior, *part.interiors]:
                found.extend(tuple(c) for c in np.asarray(ring.coords)[:-1].tolist())
    return found


def _samples(
    goal: shapely.Geometry, space: shapely.Geometry, spacing: float
) -> list[tuple[float, float]]:
    points: list[tuple[float, float]] = []
    ring = goal.boundary
    length = ring.length
    count = max(2, int(np.ceil(length / spacing)) + 1)
    for s in np.linspace(0.0, length, count):
        point = ring.interpolate(s)
        points.append((point.x, point.y))
    points.extend(tuple(c) for c in np.asarray(ring.coords).tolist())
    grown = space.buffer(1e-9)
    return [p for p in points if grown.covers(shapely.Point(p))]


class Oracle:
    """Shortest paths in one free space, with a goal's boundary points as extra nodes."""

    def __init__(
        self,
        space: shapely.Geometry,
        start: tuple[float, float],
        goals: Sequence[Polygon],
        spacing: float,
    ):
        self.space = space
        self.grown = space.buffer(1e-9)
        self.spacing = spacing
        self.goal_shapes = [shapely.Polygon(g) for g in goals]
        nodes = [start, *_corners(space)]
        self.goal_nodes: list[list[int]] = []
        for shape in self.goal_shapes:
            samples = _samples(shape, space, spacing)
            self.goal_nodes.append(list(range(len(nodes), len(nodes) + len(samples))))
            nodes.extend(samples)
        self.nodes = np.array(nodes, dtype=float)
        n = len(nodes)
        i, j = np.triu_indices(n, k=1)
        segments = shapely.linestrings(np.stack([self.nodes[i], self.nodes[j]], axis=1))
        seen = np.asarray(shapely.covers(self.grown, segments), dtype=bool)
        i, j = i[seen], j[seen]
        w = np.maximum(np.hypot(*(self.nodes[i] - self.nodes[j]).T), 1e-15)
        rows, cols, weights = np.concatenate([i, j]), np.concatenate([j, i]), np.concatenate([w, w])
        graph = csr_matrix((weights, (rows, cols)), shape=(n, n))
        self.dist = dijkstra(graph, directed=False)

    def reach(self, goal: int) -> Interval:
        """The shortest path from the start into goal ``goal``."""
        if self.goal_shapes[goal].buffer(1e-9).covers(shapely.Point(self.nodes[0])):
            return Interval(0.0, 0.0)
        upper = float(min(self.dist[0, k] for k in self.goal_nodes[goal]))
        return Interval(max(0.0, upper - self.spacing / 2), upper)

    def sequence(self, first: int, second: int) -> Interval:
        """The shortest path from the start into ``first``, then into ``second``."""
        start_in = self.goal_shapes[first].buffer(1e-9).covers(shapely.Point(self.nodes[0]))
        via = [0] if start_in else self.goal_nodes[first]
        best = np.inf
        for k in via:
            onward = (
                0.0
                if self.goal_shapes[second].buffer(1e-9).covers(shapely.Point(self.nodes[k]))
                else min(self.dist[k, m] for m in self.goal_nodes[second])
            )
            best = min(best, self.dist[0, k] + onward)
        return Interval(max(0.0, float(best) - self.spacing), float(best))

    def _onward(self, k: int, goal: int) -> float:
        """From node ``k`` into goal ``goal`` (0 when already inside)."""
        if self.goal_shapes[goal].buffer(1e-9).covers(shapely.Point(self.nodes[k])):
            return 0.0
        return float(min(self.dist[k, m] for m in self.goal_nodes[goal]))

    def feasible_sequence(self, first: int, second: int, reach: float, step: float) -> bool:
        """Whether some path enters ``first`` within ``reach`` (a length) and from there
        enters ``second`` within ``step`` more: a witness among the points placed on
        ``first``'s boundary (every such path is achievable; False proves nothing)."""
        start_in = self.goal_shapes[first].buffer(1e-9).covers(shapely.Point(self.nodes[0]))
        via = [0] if start_in else self.goal_nodes[first]
        return any(self.dist[0, k] <= reach and self._onward(k, second) <= step for k in via)

    def feasible_order(self, goals: Sequence[int], limits: Sequence[float]) -> bool:
        """Whether a path enters ``goals[0]`` within ``limits[0]``, then ``goals[1]`` within
        ``limits[1]`` from the start (lengths), for two goals: a witness as above."""
        first, second = goals
        start_in = self.goal_shapes[first].buffer(1e-9).covers(shapely.Point(self.nodes[0]))
        via = [0] if start_in else self.goal_nodes[first]
        return any(
            self.dist[0, k] <= limits[0] and self.dist[0, k] + self._onward(k, second) <= limits[1]
            for k in via
        )
