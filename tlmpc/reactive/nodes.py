"""The robot's motion in a reactive game, and what a strategy node shows of it.

The game's variables of the motion are ``face`` (where the robot is), ``goal`` (the face it
heads for) and ``moved`` (whether it left its face since the last step).  Both strategy
steppers, the explicit machine of ``strategy.json`` and the symbolic one, store a node as a
valuation of the game's variables and read the robot's behaviour off it the same way
(:class:`NodeBehaviour`).  Nothing here imports the synthesis: the executor loads it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from tlmpc.mission.model import FACE, GOAL, MOVED

#: A value of a game variable: a bool, or an integer of a bounded range.
Value = int | bool


class NodeBehaviour:
    """The goal and actions a strategy node shows, for a stepper with ``nodes`` (valuations)
    and ``actions`` (the robot's action names)."""

    nodes: Sequence[Mapping[str, Value]]
    actions: Sequence[str]

    def goal(self, node: int) -> int:
        """The face the robot heads for at ``node``."""
        return int(self.nodes[node][GOAL])

    def action_values(self, node: int) -> dict[str, bool]:
        """The actions' values at ``node``."""
        return {a: bool(self.nodes[node][a]) for a in self.actions}

    def behaviour(self, node: int) -> tuple[Value, ...]:
        """What the robot shows at ``node``: its goal and its actions (not its memory)."""
        return (self.goal(node), *(bool(self.nodes[node][a]) for a in self.actions))


__all__ = ["FACE", "GOAL", "MOVED", "NodeBehaviour", "Value"]
