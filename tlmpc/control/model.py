"""Controllers (stage 6 output): one affine feedback law u = Kx + g per plan step."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from tlmpc.abstraction.model import FloatArray
from tlmpc.base.content import ContentEquality


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class CellField(ContentEquality):
    """The continuous piecewise affine field of a cell step, one affine law u = K x + g per
    triangle of the cell (the interpolation of the vertex velocities).

    ``neighbours[k, i]`` says what lies across facet i of piece k: the index of another
    piece, ``KEPT`` (-1: a side of the cell the field keeps) or ``EXIT`` (-2: the interface
    the step leaves by). ``direction`` is the flow direction xi of a move (the robot's xi·x
    grows at ``exit_speed`` minus the disturbance or faster); a stay has none and converges
    to its controller's target."""

    triangles: tuple[int, ...]
    vertices: FloatArray  # (k, 3, 2)
    velocities: FloatArray  # (k, 3, 2)
    gains: FloatArray  # (k, 2, 2)
    offsets: FloatArray  # (k, 2)
    neighbours: tuple[tuple[int, int, int], ...]
    direction: tuple[float, float] | None
    cell: int
    target_cell: int | None
    #: the index (into the witness's prefix + cycle) of the triangle whose automaton state
    #: the step ends in: the one it leaves the cell from (a stay: the last)
    plan_index: int = 0

    def piece_of(self, triangle: int) -> int | None:
        """The piece of ``triangle`` (None when it is not in the cell)."""
        try:
            return self.triangles.index(triangle)
        except ValueError:
            return None


#: What lies across a cell piece's facet: a kept side of the cell, or the exit interface.
KEPT = -1
EXIT = -2


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class StepController(ContentEquality):
    """The field used while the plan is at ``step``: in ``triangle``, leaving by ``exit_edge``.

    ``exit_edge`` is the index of the facet opposite that vertex (None for a stay, which
    converges to ``target``).  ``exit_speed`` is the guaranteed speed across the exit edge
    (for a stay: the guaranteed inward speed on every edge); ``exit_time_bound`` bounds the
    time to leave from any point of the closed triangle.

    ``kind`` is ``"affine"`` for the fields above and ``"vertex"`` for a vertex passage: the
    pursuit law u(x) = max_speed (v - x) / |v - x| toward the corner ``target`` = v, which
    every point of the triangle reaches along a straight segment in at most
    ``exit_time_bound``; the robot then goes on in ``next_triangle`` from v (see
    docs/control.md).  A vertex step has no exit edge; ``gain`` and ``offset`` are zero and
    ``velocities`` hold the pursuit velocities at the corners (zero at v itself).  A
    ``"cell"`` step runs the field of a convex cell (:class:`CellField`, see is_cell).
    """

    step: int
    triangle: int
    exit_edge: int | None
    next_triangle: int | None
    vertices: FloatArray  # (3, 2)
    velocities: FloatArray  # (3, 2), at the vertices
    gain: FloatArray  # K (2, 2)
    offset: FloatArray  # g (2,)
    exit_speed: float
    exit_time_bound: float
    target: tuple[float, float] | None = None
    kind: str = "affine"
    cell: CellField | None = None

    @property
    def is_stay(self) -> bool:
        """True for the stay field that converges inside its triangle."""
        if self.kind == "cell":
            return self.cell is not None and self.cell.direction is None
        return self.exit_edge is None and self.kind == "affine"

    @property
    def is_cell(self) -> bool:
        """True for a cell step (``kind`` "cell"): the piecewise affine field of a convex
        cell (``cell``), leaving it across its interface or, without ``cell.direction``,
        converging to ``target`` inside it; ``triangle``, ``vertices`` and ``gain`` are those
        of the plan's first triangle in the cell."""
        return self.kind == "cell"

    @property
    def is_vertex(self) -> bool:
        """True for a vertex passage (pursuit of the corner ``target``)."""
        return self.kind == "vertex"


@dataclass(frozen=True, slots=True, kw_only=True)
class VelocityJump:
    """A vertex where the field is discontinuous between two consecutive steps, and why."""

    step: int
    vertex: int
    position: tuple[float, float]
    reason: str


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Controllers(ContentEquality):
    """Every step's controller; ``loop_start`` is the first step of a moving cycle."""

    steps: tuple[StepController, ...]
    loop_start: int | None
    max_speed: float
    margin: float
    jumps: tuple[VelocityJump, ...] = ()
    stats: Mapping[str, Any] = field(default_factory=dict)
