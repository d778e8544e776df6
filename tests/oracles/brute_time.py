"""A brute-force shortest-time search over reach plans on small meshes.

For the task "visit g" every plan is a path of triangles from the start triangle to a first
triangle of g, where the robot then stays.  This oracle enumerates the simple such paths
(no triangle twice, so no bounce) depth-first up to a budget, builds each one's witness by
hand, and times it with tlmpc's own controller synthesis and exact simulation (the times of a
given plan are theirs to give; which plan is fastest is decided here, not by the planner).
The time of a plan is the first instant its trajectory is in a triangle of g, read off the
trace's samples.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from tlmpc.abstraction.model import Abstraction
from tlmpc.base.errors import TlmpcError
from tlmpc.control import synthesize
from tlmpc.mission.model import Mission
from tlmpc.planning.model import Witness
from tlmpc.simulate import simulate


@dataclass(frozen=True)
class Fastest:
    """The least time over the enumerated paths, the path, how many were timed, and whether
    the enumeration was complete (every simple path within the budget)."""

    time: float
    path: tuple[int, ...]
    timed: int
    complete: bool


def simple_paths(
    abstraction: Abstraction, start: int, goal: np.ndarray, budget: int
) -> Iterator[tuple[int, ...]]:
    """Simple triangle paths from ``start`` that end at their first triangle in ``goal``
    (at most ``budget`` of them), in depth-first order."""
    count = 0
    stack: list[tuple[int, ...]] = [(start,)]
    while stack and count < budget:
        path = stack.pop()
        here = path[-1]
        if goal[here]:
            count += 1
            yield path
            continue
        for other in abstraction.neighbors[here].tolist():
            if other >= 0 and other not in path:
                stack.append((*path, other))


def path_witness(abstraction: Abstraction, path: tuple[int, ...]) -> Witness:
    """The witness of "follow ``path``, then stay in its last triangle"."""
    return Witness(
        prefix=path[:-1],
        cycle=path[-1:],
        prefix_states=tuple(0 for _ in path[:-1]),
        cycle_states=(0,),
        word=tuple(abstraction.labels(t) for t in path),
        cost=0.0,
        metric="time",
        beta=1.0,
        prefix_cost=0.0,
        cycle_cost=0.0,
    )


def arrival(mission: Mission, abstraction: Abstraction, path: tuple[int, ...]) -> float:
    """When the trajectory of ``path`` first is in its last triangle (inf: not realised)."""
    try:
        controllers = synthesize(abstraction, path_witness(abstraction, path), mission.robot)
        trace = simulate(abstraction, controllers, mission)
    except TlmpcError:
        return float("inf")
    inside = [j for j, t in enumerate(trace.triangles) if t == path[-1]]
    return float(trace.times[inside[0]]) if inside else float("inf")


def fastest_visit(
    mission: Mission, abstraction: Abstraction, start: int, region: str, budget: int = 400
) -> Fastest:
    """The fastest simple plan from triangle ``start`` into ``region`` (see the module doc)."""
    goal = np.array([region in abstraction.labels(t) for t in range(abstraction.num_triangles)])
    best: tuple[float, tuple[int, ...]] = (float("inf"), (start,))
    timed = 0
    for path in simple_paths(abstraction, start, goal, budget + 1):
        if timed == budget:
            return Fastest(best[0], best[1], timed, complete=False)
        timed += 1
        found = arrival(mission, abstraction, path)
        if found < best[0]:
            best = (found, path)
    return Fastest(best[0], best[1], timed, complete=True)
