"""Controllers (stage 6 output): one affine feedback law u = Kx + g per plan step."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from tlmpc.abstraction.model import FloatArray
from tlmpc.base.content import ContentEquality


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
    ``velocities`` hold the pursuit velocities at the corners (zero at v itself).
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

    @property
    def is_stay(self) -> bool:
        """True for the stay field that converges inside its triangle."""
        return self.exit_edge is None and self.kind == "affine"

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
