"""Monte Carlo: with ``robot.disturbance: d`` every seeded run under |w| <= d satisfies the
task, on the shipped specs and on generated missions; pushed harder, runs recover; unicycles
satisfy the shipped specs.

The verdict oracle is independent of the executor: the verifier (which shares no code with
planning, control or the runtime) evaluates each trace, and shapely checks that the reference
point never enters an obstacle nor leaves the workspace.  Budgets follow the hypothesis
profile (``ci`` smaller, never zero).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
import yaml
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st
from strategies import missions

import tlmpc
from tlmpc.runtime import Executor, make_disturbance, run_closed_loop
from tlmpc.runtime.closed_loop import ClosedLoopRun, default_dt
from tlmpc.runtime.disturbance import Disturbance
from tlmpc.verify import verify_document

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ("example1", "example6", "example7", "example8", "patrol", "reach-avoid")
#: Seeds per spec and disturbance model: a quarter of the profile's budget per ten.
SEEDS = max(2, settings().max_examples // 50)
FloatArray = np.ndarray[Any, np.dtype[np.float64]]


def _spec(name: str, **robot: Any) -> dict[str, Any]:
    document: dict[str, Any] = yaml.safe_load((ROOT / "specs" / f"{name}.yaml").read_text())
    document["robot"].update(robot)
    return document


_COMPILED: dict[str, tlmpc.Compiled] = {}


def _compiled(name: str, **robot: Any) -> tlmpc.Compiled:
    key = repr((name, sorted(robot.items())))
    if key not in _COMPILED:
        _COMPILED[key] = tlmpc.compile(_spec(name, **robot))
    return _COMPILED[key]


class _Bounded:
    """Wraps a disturbance and records the largest norm it produced."""

    def __init__(self, inner: Disturbance) -> None:
        self.inner, self.largest = inner, 0.0

    def __call__(self, t: float, point: FloatArray, executor: Executor) -> FloatArray:
        w = self.inner(t, point, executor)
        self.largest = max(self.largest, float(np.hypot(w[0], w[1])))
        return w


def _stays_in_free_space(trace: Any) -> bool:
    """Shapely: the reference point's polyline stays in the workspace, outside every hole."""
    points = [(x, y) for _, x, y in trace["points"]]
    path = shapely.LineString(points) if len(points) > 1 else shapely.Point(points[0])
    outer = shapely.Polygon(trace["workspace"]["boundary"])
    holes = [shapely.Polygon(h) for h in trace["workspace"].get("holes", [])]
    return outer.buffer(1e-9).covers(path) and not any(
        path.intersection(h).length > 1e-9 for h in holes
    )


def _run(
    compiled: tlmpc.Compiled, model: str, bound: float, seed: int, cycles: int = 2, **kw: Any
) -> tuple[ClosedLoopRun, float]:
    executor = tlmpc.executor(compiled)
    speed = executor.mission.robot.max_speed + bound
    hold = 10 * default_dt(executor.plan, speed)
    disturbance = _Bounded(make_disturbance(model, bound, seed, hold))  # type: ignore[arg-type]
    run = run_closed_loop(executor, disturbance, bound=bound, cycles=cycles, **kw)
    return run, disturbance.largest


def _check_satisfied(run: ClosedLoopRun) -> None:
    verdict = verify_document(run.trace)
    assert verdict.satisfied, [v.message for v in verdict.violations]
    assert _stays_in_free_space(run.trace)
    assert run.completed


@pytest.mark.parametrize("model", ["random", "adversarial"])
@pytest.mark.parametrize("name", SHIPPED)
def test_every_run_within_the_declared_bound_satisfies_the_shipped_spec(
    name: str, model: str
) -> None:
    bound = 0.1 * float(_spec(name)["robot"].get("max_speed", 1.0))
    compiled = _compiled(name, disturbance=bound)
    for seed in range(SEEDS if model == "random" else 1):
        run, largest = _run(compiled, model, bound, seed)
        assert largest <= bound * (1 + 1e-12)
        _check_satisfied(run)
        # Within the bound the robot never leaves its plan: nothing to recover from.
        assert run.recoveries == ()


@settings(
    max_examples=max(3, settings().max_examples // 20),
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(missions())
def test_every_run_within_the_declared_bound_satisfies_a_generated_mission(
    document: dict[str, Any],
) -> None:
    bound = 0.05
    document["robot"]["disturbance"] = bound
    try:
        compiled = tlmpc.compile(document)
    except tlmpc.TlmpcError:
        assume(False)  # no plan, or a corner no field can hold against d (both located)
    for model in ("random", "adversarial"):
        run, largest = _run(compiled, model, bound, seed=1, cycles=1)
        assert largest <= bound * (1 + 1e-12)
        _check_satisfied(run)
        assert run.recoveries == ()


def _corridor() -> dict[str, Any]:
    return {
        "version": 1,
        "name": "corridor",
        "workspace": {"boundary": {"rect": [0, 0, 10, 4]}},
        "regions": {"a": {"rect": [4, 3, 6, 4]}, "b": {"rect": [8.5, 0, 10, 1]}},
        "robot": {"start": [1, 1], "max_speed": 1.0, "disturbance": 0.05},
        "task": ["visit a and b infinitely often"],
    }


def test_runs_pushed_above_the_bound_recover_and_still_satisfy_the_task() -> None:
    """Random pushes of 0.8 against a declared 0.05: the robot is pushed off its plan, the
    executor re-enters or re-plans, and (no task forbids any place here, so a plan always
    exists) every run completes its laps and satisfies the task."""
    compiled = tlmpc.compile(_corridor())
    recovered = 0
    for seed in range(2 * SEEDS):
        run, largest = _run(compiled, "random", 0.8, seed)
        assert largest <= 0.8 * (1 + 1e-12)
        _check_satisfied(run)
        recovered += len(run.recoveries)
    assert recovered > 0, "pushes this strong must throw the robot off its plan"


@pytest.mark.slow
@pytest.mark.parametrize("name", SHIPPED)
def test_a_unicycle_satisfies_the_shipped_spec(name: str) -> None:
    compiled = _compiled(name, model="unicycle", offset=0.1)
    for heading in (0.0, 2.0):
        run, _ = _run(compiled, "random", 0.0, 0, cycles=1, heading=heading)
        _check_satisfied(run)


@pytest.mark.slow
@pytest.mark.parametrize("model", ["random", "adversarial"])
def test_a_disturbed_unicycle_satisfies_its_task(model: str) -> None:
    compiled = _compiled("patrol", model="unicycle", offset=0.1, disturbance=0.1)
    for seed in range(SEEDS if model == "random" else 1):
        run, _ = _run(compiled, model, 0.1, seed, heading=1.0)
        _check_satisfied(run)
        assert run.recoveries == ()


class _Shove:
    """At ``at`` seconds, moves the robot to ``target`` in one sample (unless the straight
    shove would cross an obstacle): a push far above any bound, continuous in the trace."""

    def __init__(self, at: float, target: FloatArray, dt: float, holes: list[Any]) -> None:
        self.at, self.target, self.dt, self.holes = at, target, dt, holes
        self.done = False

    def __call__(self, t: float, point: FloatArray, executor: Executor) -> FloatArray:
        if self.done or t < self.at:
            return np.zeros(2)
        self.done = True
        shove = shapely.LineString([tuple(point), tuple(self.target)])
        if any(shove.intersects(hole) for hole in self.holes):
            return np.zeros(2)
        velocity: FloatArray = (self.target - point) / self.dt - executor.velocity(point)
        return velocity


@settings(
    max_examples=max(3, settings().max_examples // 20),
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(
    missions(),
    st.floats(0.0, 30.0),
    st.floats(0.05, 11.95),
    st.floats(0.05, 7.95),
)
def test_a_shoved_run_recovers_soundly_on_a_generated_mission(
    document: dict[str, Any], at: float, x: float, y: float
) -> None:
    """Shoved anywhere at any time: whenever the executor completes its run it satisfies the
    task (re-entries and re-plans are sound), and when it reports the task violated, the
    verifier agrees."""
    try:
        compiled = tlmpc.compile(document)
    except tlmpc.TlmpcError:
        assume(False)
    executor = tlmpc.executor(compiled)
    holes = [shapely.Polygon(h) for h in compiled.artifacts["mission.json"]["workspace"]["holes"]]
    target = np.array([x, y])
    assume(not any(hole.buffer(1e-6).covers(shapely.Point(x, y)) for hole in holes))
    dt = default_dt(executor.plan, executor.mission.robot.max_speed)
    run = run_closed_loop(executor, _Shove(at, target, dt, holes), bound=0.0, dt=dt, cycles=1)
    verdict = verify_document(run.trace)
    event(f"status {run.progress.status}, completed {run.completed}")
    event(f"recovered {bool(run.recoveries)}")
    if run.completed and run.progress.status == "following":
        assert verdict.satisfied, [v.message for v in verdict.violations]
        assert _stays_in_free_space(run.trace)
    if run.progress.status == "violated":
        assert not verdict.satisfied
