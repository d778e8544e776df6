"""Closed-loop simulation with the executor in the loop and a bounded disturbance.

The executor is sampled every ``dt`` seconds and its command is held until the next sample
(zero-order hold, as on a real robot); the disturbance w is held likewise.  For a point robot
the motion over a sample is then exactly the straight move dt·(u + w); for a unicycle the
axle follows the exact arc of the held (v, ω), shifted by dt·w, and the trace records the
reference point at every sample.  The executor reads each move with a mesh walk, so it sees
every triangle the trace's polyline passes through: the verifier and the executor judge the
same trajectory.

A run ends after ``cycles`` completed laps of the cycle (the trace then declares its last lap
as the loop that repeats forever: ``end: loop``), after ``cycles`` dwell times in a final
stay (``end: stay``), or at ``duration`` (cut back to the last completed lap when there is
one, else ``end: open``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tlmpc.abstraction.model import triangle_inradius
from tlmpc.base.errors import Diagnostic, UsageError, error
from tlmpc.ltl.ast import bounded_operators
from tlmpc.runtime.disturbance import Disturbance
from tlmpc.runtime.executor import Executor, RunPlan
from tlmpc.runtime.model import Progress, Recovery
from tlmpc.runtime.unicycle import unicycle_flow

#: Default sample period: this fraction of the smallest inradius of the plan's triangles
#: crossed at the largest possible speed (a held command then never overshoots a triangle).
DT_FRACTION = 0.1
#: A run gives up (``end: open``) after this many times its nominal duration.
TIME_CAP_FACTOR = 10.0

#: Samples a run may take (the verifier's limit for a log): a unicycle's default dt takes
#: some 10^5 samples for two laps of a shipped mission; a dt of 1e-9 would take forever.
MAX_SAMPLES = 2_000_000
#: Samples a run of a task with time bounds may take: the verifier then searches every
#: bound's windows over the whole trace, some four times the memory and time a sample costs
#: otherwise (a 250,000-sample run with two bounds: 51 CPU s and 1.0 GB, without them 11 s
#: and 0.4 GB), so a quarter of the budget.
MAX_TIMED_SAMPLES = 500_000


def sample_budget(executor: Executor) -> int:
    """How many samples a run of ``executor``'s mission may take."""
    return MAX_TIMED_SAMPLES if bounded_operators(executor.mission.formula) else MAX_SAMPLES


@dataclass(frozen=True, slots=True, kw_only=True)
class ClosedLoopRun:
    """A simulated run: the ``trace.json`` document, and what the executor reported."""

    trace: Mapping[str, Any] = field(repr=False)
    progress: Progress
    recoveries: tuple[Recovery, ...]
    samples: int
    dt: float
    completed: bool  # the requested laps / dwell were reached (else the trace ends open)


def default_dt(plan: RunPlan, speed: float) -> float:
    """:data:`DT_FRACTION` of the plan's smallest inradius over the largest speed."""
    return DT_FRACTION * min(triangle_inradius(step.vertices) for step in plan.steps) / speed


def _dwell(plan: RunPlan) -> float:
    """One "cycle" of a final stay: the stay triangle's diameter over its inward speed."""
    stay = plan.steps[-1]
    diameter = max(
        float(np.linalg.norm(stay.vertices[i] - stay.vertices[(i + 1) % 3])) for i in range(3)
    )
    return diameter / max(stay.exit_speed, 1e-12)


def _nominal(plan: RunPlan, cycles: int) -> float:
    times = [step.exit_time_bound for step in plan.steps if math.isfinite(step.exit_time_bound)]
    per_lap = sum(times[plan.loop_start :]) if plan.loop_start is not None else _dwell(plan)
    return sum(times) + cycles * per_lap


def initial_pose(executor: Executor, heading: float) -> tuple[float, ...]:
    """The pose whose reference point is the mission's start."""
    robot = executor.mission.robot
    x, y = robot.start
    if robot.model != "unicycle":
        return (x, y)
    return (x - robot.offset * math.cos(heading), y - robot.offset * math.sin(heading), heading)


def run_closed_loop(
    executor: Executor,
    disturbance: Disturbance,
    *,
    bound: float,
    cycles: int | None = 2,
    duration: float | None = None,
    dt: float | None = None,
    heading: float = 0.0,
    source: str | None = None,
) -> ClosedLoopRun:
    """Simulate ``executor`` under ``disturbance`` (|w| <= ``bound``; see the module doc).

    Give ``cycles`` (laps of the cycle, or dwell times of a stay) or ``duration`` (seconds).
    ``source`` names the compiled output in diagnostics.
    """
    robot = executor.mission.robot
    speed = robot.max_speed + bound
    step_time = dt if dt is not None else default_dt(executor.plan, speed)
    if duration is not None:
        horizon = duration
        expected = duration / step_time
    else:
        nominal = _nominal(executor.plan, cycles or 1)
        horizon = TIME_CAP_FACTOR * max(nominal, step_time)
        expected = nominal / step_time
    budget = sample_budget(executor)
    if not expected <= budget:
        length = duration if duration is not None else nominal
        raise UsageError(
            _over_budget(expected, length, step_time, dt is not None, cycles, source, budget)
        )
    pose = initial_pose(executor, heading)
    t = 0.0
    samples: list[tuple[float, float, float]] = []
    marks: list[int] = []  # sample indices where a lap of the current plan starts
    plan, previous_step = executor.plan, -1
    stay_since: float | None = None
    completed = False
    recovered = len(executor.recoveries)
    while True:
        command = executor.command(pose, t)
        point = executor.reference_point(pose)
        samples.append((t, float(point[0]), float(point[1])))
        progress = executor.progress
        if progress.status in ("no_plan", "violated"):
            break
        if len(progress_recoveries := executor.recoveries) != recovered:
            # A re-entry or a re-plan: laps count again from the next clean start of the
            # cycle, so a declared loop is always one whole lap of the plan being followed.
            recovered = len(progress_recoveries)
            plan, previous_step, marks, stay_since = executor.plan, -1, [], None
        if plan.loop_start is not None:
            if progress.step == plan.loop_start and previous_step != plan.loop_start:
                marks.append(len(samples) - 1)
                if cycles is not None and duration is None and len(marks) > cycles:
                    completed = True
                    break
        elif progress.phase == "stay":
            stay_since = t if stay_since is None else stay_since
            if cycles is not None and duration is None and t - stay_since >= cycles * _dwell(plan):
                completed = True
                break
        else:
            stay_since = None
        previous_step = progress.step
        # the time cap, or the sample budget: a run that needs more samples than expected
        # (recoveries, or t + dt == t at a tiny dt) ends there, inconclusive
        if t >= horizon or len(samples) >= budget:
            completed = duration is not None and t >= horizon
            break
        w = disturbance(t, point, executor)
        if executor.is_unicycle:
            x, y, theta = unicycle_flow(pose, command[0], command[1], step_time)
            pose = (x + step_time * float(w[0]), y + step_time * float(w[1]), theta)
        else:
            pose = (
                pose[0] + step_time * (command[0] + float(w[0])),
                pose[1] + step_time * (command[1] + float(w[1])),
            )
        t += step_time
    loop_start: int | None = None
    end = "open"
    if plan.loop_start is not None and len(marks) >= 2 and executor.progress.status == "following":
        samples = samples[: marks[-1] + 1]
        loop_start, end = marks[-2], "loop"
    elif stay_since is not None and executor.progress.status == "following":
        end = "stay"
    if end == "open":
        completed = False
    return ClosedLoopRun(
        trace=_trace_document(executor, samples, loop_start, end, speed),
        progress=executor.progress,
        recoveries=executor.recoveries,
        samples=len(samples),
        dt=step_time,
        completed=completed,
    )


def _over_budget(
    expected: float,
    length: float,
    step_time: float,
    given: bool,
    cycles: int | None,
    source: str | None,
    budget: int,
) -> Diagnostic:
    """R024: a run of ``length`` seconds, ``expected`` samples of ``step_time`` (the ``--dt``
    given, or the default from the mesh), would pass ``budget``; what would fit
    instead.  Located at ``--dt`` when given, else at the output whose plan sets the default
    dt and the run's nominal length."""
    place: str | None = source
    if given:
        period, place = f"--dt {step_time:g} s", f"--dt {step_time:g}"
    else:
        period = (
            f"the default dt {step_time:g} s (a tenth of the smallest inradius of the plan's "
            "triangles over max_speed + the disturbance bound)"
        )
    fewer = ", fewer --cycles" if cycles is not None and cycles > 1 else ""
    return error(
        "R024",
        f"the run would take about {expected:.3g} samples, more than the budget of "
        f"{budget:,}{' (a task with time bounds)' if budget < MAX_SAMPLES else ''}: "
        f"{length:.4g} s at {period}",
        hint=f"give --dt {_three_digits(length / budget, math.ceil):g} or larger{fewer}, "
        f"or --duration {_three_digits(budget * step_time, math.floor):g} or shorter",
        file=place,
    )


def _three_digits(value: float, rounding: Callable[[float], int]) -> float:
    """``value`` rounded to three significant digits by ``rounding`` (math.ceil: a value
    that is no smaller, math.floor: no larger), so a hint's printed value keeps its promise."""
    if not 0.0 < value < math.inf:
        return value
    scale = 10.0 ** (math.floor(math.log10(value)) - 2)
    if not 0.0 < scale < math.inf:  # (at the ends of the double range: as it is)
        return value
    return float(f"{rounding(value / scale) * scale:.3g}")


def _trace_document(
    executor: Executor,
    samples: list[tuple[float, float, float]],
    loop_start: int | None,
    end: str,
    speed: float,
) -> dict[str, Any]:
    """``trace.json`` of the reference point (``max_speed`` bounds its speed: u plus w)."""
    from tlmpc.simulate.exact import trace_header

    return {
        **trace_header(executor.mission, speed),
        "points": [list(sample) for sample in samples],
        "loop_start": loop_start,
        "end": end,
    }
