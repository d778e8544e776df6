"""The ``time`` metric: seconds per move of the transition system D.

A move ``(t, s, i)`` leaves triangle ``t`` through edge ``i`` after entering it through edge
``s`` (``s = 3``: starting in ``t``).  Its weight under the ``time`` metric is

* the **measured** time, when the move was part of a plan whose controllers were synthesised
  and whose trajectory was simulated exactly (the time the robot spent in ``t`` on that step,
  from its entry point on edge ``s`` to its exit on edge ``i``; see
  :mod:`tlmpc.pipeline.mintime`), else
* the **estimate** ``length / max_speed``: the move's midpoint-to-midpoint length (the
  ``length`` metric's weight) at the robot's top speed.  The controllers never exceed
  ``max_speed``, so a step that crosses the triangle along that segment takes at least this
  long; an estimate, not a bound (the robot's path through a triangle may be shorter than the
  segment between the midpoints).

Measured times are keyed by the triangle's three mesh vertices (in the mesh's order) rather
than its index, so they still name the same move on a copy of the mesh refined elsewhere.
The weights form one array over the (triangle, slot, exit) grid that the built product, the
product expanded on demand and the vertex passages all read (:func:`move_time_table`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from tlmpc.abstraction.model import Abstraction, FloatArray

#: A move named independently of the triangle's index: its corners (mesh vertex ids, in the
#: triangle's order), the entry slot and the exit edge.
MoveKey = tuple[tuple[int, int, int], int, int]


@dataclass(frozen=True, slots=True)
class MoveTimes:
    """What the ``time`` metric weighs moves with: the robot's top speed (the estimate's
    divisor) and the measured seconds of moves of earlier plans (see the module doc)."""

    speed: float
    measured: Mapping[MoveKey, float] = field(default_factory=dict)

    def seconds_per_length(self) -> float:
        """The estimate's factor: seconds per unit of length at top speed."""
        return 1.0 / max(self.speed, 1e-12)


def move_key(abstraction: Abstraction, triangle: int, slot: int, exit_edge: int) -> MoveKey:
    """The key of the move ``(triangle, slot, exit_edge)`` of ``abstraction``."""
    a, b, c = (int(v) for v in abstraction.triangles[triangle])
    return ((a, b, c), slot, exit_edge)


def move_time_table(abstraction: Abstraction, lengths: FloatArray, times: MoveTimes) -> FloatArray:
    """(m, SLOTS, 3) seconds per move: ``lengths`` (the ``length`` metric's weights on the
    same grid) at top speed, replaced by the measured time where there is one."""
    table: FloatArray = lengths * times.seconds_per_length()
    if not times.measured:
        return table
    index = {
        (int(a), int(b), int(c)): t for t, (a, b, c) in enumerate(abstraction.triangles.tolist())
    }
    for (corners, slot, exit_edge), seconds in sorted(times.measured.items()):
        triangle = index.get(corners)
        if triangle is not None:
            # positive weights: the searches need them (a step of zero time is a rounding)
            table[triangle, slot, exit_edge] = max(float(seconds), 1e-9)
    return table
