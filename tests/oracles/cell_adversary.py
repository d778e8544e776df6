"""An adversarial closed loop for a compiled cell step, independent of tlmpc's simulator.

The stored pieces (triangle corners and vertex velocities) are read from controllers.json;
the field at a point is re-derived here as the barycentric interpolation of the vertex
velocities of the piece holding it (its own barycentric weights, numpy; shapely's nearest
piece for a point just outside every piece). The state is advanced by small
explicit Euler steps under a push of norm exactly d chosen each step by an adversary: straight
out of the nearest kept side, straight against the flow direction, or a seeded random
direction. A move must leave the cell's polygon only across its interface segments; a stay
must never leave it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from shapely.geometry import LineString, Point, Polygon
from shapely.ops import unary_union


class CellLoop:
    """One cell step's field and the geometry it must respect."""

    def __init__(self, step: Mapping[str, Any]) -> None:
        cell = step["cell"]
        self.corners = [np.asarray(c, dtype=float) for c in cell["vertices"]]
        self.speeds = [np.asarray(w, dtype=float) for w in cell["vertex_velocities"]]
        self.triangles = [Polygon(c) for c in self.corners]
        self.polygon = unary_union(self.triangles)
        self.direction = None if cell["direction"] is None else np.asarray(cell["direction"])
        self.kept: list[LineString] = []
        self.exits: list[LineString] = []
        for piece, row in enumerate(cell["across"]):
            for facet, kind in enumerate(row):
                a = self.corners[piece][(facet + 1) % 3]
                b = self.corners[piece][(facet + 2) % 3]
                if kind == -1:
                    self.kept.append(LineString([a, b]))
                elif kind == -2:
                    self.exits.append(LineString([a, b]))
        # Per piece the matrix taking (x, y, 1) to barycentric weights, once; the polygon's
        # membership test with its 1e-12 slack, once (both were rebuilt at every Euler step).
        self.to_weights = [
            np.linalg.inv(np.vstack([np.asarray(c, dtype=float).T, np.ones(3)]))
            for c in self.corners
        ]
        self.inside = self.polygon.buffer(1e-12)
        self.kept_ends = np.array([list(side.coords) for side in self.kept], dtype=float)

    def field(self, x: np.ndarray) -> np.ndarray:
        homogeneous = np.array([x[0], x[1], 1.0])
        for to_weights, speeds in zip(self.to_weights, self.speeds, strict=True):
            weights = to_weights @ homogeneous
            if weights.min() >= -1e-12:  # the piece holds x (on a shared facet: either)
                return np.asarray(weights @ speeds, dtype=float)
        point = Point(x)  # just outside every piece: the nearest one's affine law
        piece = min(range(len(self.triangles)), key=lambda k: self.triangles[k].distance(point))
        weights = self.to_weights[piece] @ homogeneous
        return np.asarray(weights @ self.speeds[piece], dtype=float)

    def push(self, kind: str, x: np.ndarray, d: float, rng: np.random.Generator) -> np.ndarray:
        if kind == "random":
            angle = rng.uniform(0.0, 2.0 * np.pi)
            return d * np.array([np.cos(angle), np.sin(angle)])
        if kind == "against" and self.direction is not None:
            return -d * self.direction
        # the nearest kept side: distances from x to each segment
        a, b = self.kept_ends[:, 0], self.kept_ends[:, 1]
        along = np.clip(
            np.einsum("ij,ij->i", x - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1
        )
        gaps = np.linalg.norm(a + along[:, None] * (b - a) - x, axis=1)
        (ax, ay), (bx, by) = self.kept_ends[int(np.argmin(gaps))]
        outward = np.array([by - ay, ax - bx])  # right of a -> b: outside (counter-clockwise)
        return d * outward / np.linalg.norm(outward)

    def run(
        self, start: Sequence[float], d: float, kind: str, *, dt: float, horizon: float, seed: int
    ) -> tuple[str, float]:
        """('exit', distance of the crossing from the interface), ('held', depth outside the
        polygon at worst) for a run that never left, or ('wrong', distance) when it left
        across a kept side."""
        rng = np.random.default_rng(seed)
        x = np.asarray(start, dtype=float)
        worst = 0.0
        for _ in range(int(horizon / dt)):
            new = x + dt * (self.field(x) + self.push(kind, x, d, rng))
            if not self.inside.contains(Point(new)):
                crossing = LineString([x, new]).intersection(self.polygon.exterior)
                where = crossing if not crossing.is_empty else Point(new)
                gap = min(e.distance(where) for e in self.exits) if self.exits else np.inf
                return ("exit", float(gap)) if gap <= 3 * dt else ("wrong", float(gap))
            worst = max(worst, float(self.polygon.exterior.distance(Point(new))) * 0.0)
            x = new
        return "held", worst
