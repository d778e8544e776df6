"""The plan to export: the exact trajectory of a compiled mission and its map."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from tlmpc.base.content import ContentEquality
from tlmpc.base.errors import UsageError, error

FloatArray = npt.NDArray[np.float64]
Point = tuple[float, float]
Ring = tuple[Point, ...]


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Plan(ContentEquality):
    """Samples ``[t, x, y]`` of the planned trajectory; ``loop_start`` begins the repeated cycle."""

    samples: FloatArray
    loop_start: int | None
    name: str
    boundary: Ring
    holes: tuple[Ring, ...]
    regions: dict[str, Ring]
    formula: str
    #: further pieces of free space (workspace components): outer ring and holes
    components: tuple[tuple[Ring, tuple[Ring, ...]], ...] = ()
    #: samples every export keeps: the corners of vertex passages (the plan needs the robot
    #: exactly there; a thinned path would cut the corner)
    pinned: tuple[int, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class Waypoint:
    """A pose to drive to: position, heading towards the next waypoint, planned time."""

    t: float
    x: float
    y: float
    yaw: float


def _fail(code: str, message: str, file: str, hint: str | None = None) -> UsageError:
    return UsageError(error(code, message, hint=hint, file=file))


def _ring(value: Any) -> Ring:
    return tuple((float(p[0]), float(p[1])) for p in value)


def read_plan(directory: Path) -> Plan:
    """Read ``trace.json`` and ``mission.json`` of a ``tlmpc compile`` output directory."""
    from tlmpc.io.artifacts import read_artifacts

    for name in ("trace.json", "mission.json"):
        if not (directory / name).exists():
            raise _fail(
                "M080", f"{directory} has no {name}", str(directory), _missing_hint(directory)
            )
    # each checked against its schema (finite numbers) and against the others
    documents = read_artifacts(directory, ("trace.json", "mission.json", "controllers.json"))
    trace, mission = documents["trace.json"], documents["mission.json"]
    try:
        samples = np.asarray(trace["points"], dtype=np.float64).reshape(-1, 3)
        loop = trace.get("loop_start")
        workspace = mission["workspace"]
        plan = Plan(
            samples=samples,
            loop_start=int(loop) if loop is not None else None,
            name=str(mission.get("name") or "mission"),
            boundary=_ring(workspace["boundary"]),
            holes=tuple(_ring(h) for h in workspace.get("holes") or []),
            components=tuple(
                (_ring(c["boundary"]), tuple(_ring(h) for h in c.get("holes") or []))
                for c in workspace.get("components") or []
            ),
            regions={str(k): _ring(v) for k, v in mission["regions"].items()},
            formula=str(mission.get("formula", "")),
            pinned=_passage_corners(documents.get("controllers.json"), trace, samples),
        )
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise _fail(
            "M081", f"the plan in {directory} is malformed: {exc}", str(directory)
        ) from None
    if len(plan.samples) == 0 or not np.all(np.isfinite(plan.samples)):
        raise _fail("M081", f"the trajectory in {directory} is empty or not finite", str(directory))
    return plan


def _missing_hint(directory: Path) -> str:
    """What to run to get a plan into ``directory``, from what it holds."""
    if (directory / "counterstrategy.json").exists():
        return (
            "an unrealizable reactive mission has no plan: its counterstrategy.json holds the "
            "environment's winning play (`tlmpc plot DIR` and `tlmpc view DIR` draw it)"
        )
    if (directory / "strategy.json").exists():
        # a reactive mission's path depends on what the robot senses: there is no one plan
        return (
            "a reactive mission compiles to a strategy, not a plan: run it with "
            "`tlmpc simulate DIR --sensors ... -o TRACE` and check or draw the run with "
            "`tlmpc verify TRACE` or `tlmpc view --log TRACE --mission MISSION`"
        )
    if (directory / "controllers.json").exists():
        return "the compile stopped before its trajectory: run `tlmpc stage simulate DIR`"
    return "run `tlmpc compile MISSION -o DIR` first and export from DIR"


def _passage_corners(controllers: Any, trace: Any, samples: FloatArray) -> tuple[int, ...]:
    """Indices of the samples at the corner of a vertex passage (from controllers.json, when
    the folder has it: the samples of a vertex step whose position is its corner)."""
    if controllers is None:
        return ()
    steps = controllers["steps"]
    corners = {
        int(s["step"]): (float(s["target"][0]), float(s["target"][1]))
        for s in steps
        if s.get("kind") == "vertex"
    }
    if not corners:
        return ()
    step_of = trace.get("steps") or []
    return tuple(
        index
        for index, step in enumerate(step_of)
        if step in corners and (samples[index, 1], samples[index, 2]) == corners[step]
    )


def waypoints(plan: Plan, spacing: float = 0.0) -> tuple[list[Waypoint], int | None]:
    """Samples at least ``spacing`` apart (the first, the last, the loop start and the corners
    of vertex passages always kept).

    Returns the waypoints and the index of the loop start among them (``None`` when the plan
    does not loop).  Each heading points to the next waypoint (the last keeps its predecessor's,
    a looping plan's last points back to the loop start).
    """
    samples = plan.samples
    count = len(samples)
    pinned = set(plan.pinned)
    keep: list[int] = []
    for index in range(count):
        forced = index in (0, count - 1) or index == plan.loop_start or index in pinned
        if forced or not keep:
            keep.append(index)
            continue
        last = samples[keep[-1]]
        if math.hypot(samples[index, 1] - last[1], samples[index, 2] - last[2]) >= spacing:
            keep.append(index)
    loop = keep.index(plan.loop_start) if plan.loop_start is not None else None
    result: list[Waypoint] = []
    for position, index in enumerate(keep):
        if position + 1 < len(keep):
            target = samples[keep[position + 1]]
        elif loop is not None:
            target = samples[keep[loop]]
        else:
            target = samples[index]
        dx, dy = target[1] - samples[index, 1], target[2] - samples[index, 2]
        if dx == 0.0 and dy == 0.0:
            yaw = result[-1].yaw if result else 0.0
        else:
            yaw = math.atan2(dy, dx)
        result.append(
            Waypoint(
                t=float(samples[index, 0]),
                x=float(samples[index, 1]),
                y=float(samples[index, 2]),
                yaw=yaw,
            )
        )
    return result, loop
