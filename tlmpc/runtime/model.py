"""The executor's reports: task progress and the recoveries it made (frozen, typed)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Literal

#: following: a plan step is being executed; outside: the reference point is in no triangle
#: (in an obstacle or out of the workspace: the last field is extrapolated); no_plan: no plan
#: continues the task from where the robot is (it is stopped); violated: what the robot has
#: already done violates the task (it is stopped).
Status = Literal["following", "outside", "no_plan", "violated"]
Phase = Literal["prefix", "cycle", "stay"]
RecoveryKind = Literal["reentry", "replan", "no_plan", "violated"]


@dataclass(frozen=True, slots=True, kw_only=True)
class Recovery:
    """The robot entered a triangle its plan step did not lead to, and what was done.

    ``reentry``: the plan was resumed at ``step_after`` (same triangle, an automaton state
    consistent with the history); ``replan``: a new plan was computed from there; ``no_plan``
    and ``violated``: neither was possible.
    """

    time: float
    kind: RecoveryKind
    triangle: int
    step_before: int
    step_after: int | None


@dataclass(frozen=True, slots=True, kw_only=True)
class Progress:
    """Where the robot is in its plan and in its task.

    ``step`` indexes the current plan's steps (prefix then cycle); ``laps`` counts completed
    laps of the cycle (``repeating`` once one is done); ``automaton_states`` are the states
    the task's automaton can be in after the labels actually visited; ``visits`` counts the
    entries into each region; ``replans`` and ``reentries`` count recoveries.
    """

    time: float
    status: Status
    triangle: int | None
    step: int
    phase: Phase
    laps: int
    repeating: bool
    automaton_states: tuple[int, ...]
    visits: Mapping[str, int] = field(default_factory=dict)
    replans: int = 0
    reentries: int = 0
