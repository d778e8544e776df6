"""The witness: an accepting lasso of the product D x A, projected on triangles (stage 5).

The robot's discrete run is ``prefix + cycle + cycle + ...``.  ``prefix[0]`` is the start
triangle unless the start triangle opens the cycle (then ``prefix`` is empty).  Consecutive
triangles are distinct and adjacent, the last of ``cycle`` is adjacent to its first, and no
plan bounces (``path[i-1] != path[i+1]``, across the wrap too).  A cycle of one triangle is
a *stay*: the robot converges to a point inside it.

A *vertex passage* ``(i, v)`` replaces the edge between ``path[i]`` and the next triangle
(``cycle[0]`` after the last one): the robot runs to mesh vertex ``v``, a corner of both, and
goes on from there (see :mod:`tlmpc.planning.passages`).  Such a pair shares ``v``, not an edge.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from tlmpc.base.content import ContentEquality

#: The proposition true exactly at point instants (crossings and the start) in the closed
#: convention's word.  Region names are identifiers, so no region can be called this.
POINT = "@point"


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Witness(ContentEquality):
    """A minimum-cost accepting lasso (see docs/planning.md for the optimality statement)."""

    prefix: tuple[int, ...]
    cycle: tuple[int, ...]
    prefix_states: tuple[int, ...]  # automaton state after reading each prefix triangle
    cycle_states: tuple[int, ...]  # automaton state after reading each cycle triangle
    word: tuple[tuple[str, ...], ...]  # label set of each triangle of prefix + cycle
    cost: float
    metric: Literal["length", "hops", "time"]
    beta: float
    prefix_cost: float
    cycle_cost: float
    stats: Mapping[str, Any] = field(default_factory=dict)
    passages: tuple[tuple[int, int], ...] = ()  # (index into prefix + cycle, mesh vertex)

    @property
    def is_stay(self) -> bool:
        """True when the plan ends by converging inside one triangle."""
        return len(self.cycle) == 1
