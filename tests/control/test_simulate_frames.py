"""The exact simulation computes each exit step's controller constants once (a lasso's cycle is
simulated twice) and picks its samples on Python floats: the trace is bit for bit the one the
per-step computation gives, and the samples are the grid points numpy's ``rint`` picks."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

import tlmpc.simulate.exact as exact
from tlmpc.pipeline.stages import ABSTRACTION, CONTROLLERS, MISSION, compile_mission
from tlmpc.simulate import simulate

SPECS = Path(__file__).resolve().parents[2] / "specs"


@pytest.mark.parametrize("name", ["patrol.yaml", "example1.yaml", "deadline.yaml"])
def test_reused_frames_give_the_per_step_trace(name: str, monkeypatch: Any) -> None:
    result = compile_mission(SPECS / name, until="control")
    controllers = result.compilation.get(CONTROLLERS)
    mission = result.compilation.get(MISSION)
    reused = simulate(None, controllers, mission)  # type: ignore[arg-type]
    computed: list[int] = []
    fresh_step = exact._exit_step

    def per_step(controller: Any, x0: Any, frame: Any = None) -> Any:
        computed.append(controller.step)
        return fresh_step(controller, x0)  # the frame computed again, from the controller

    monkeypatch.setattr(exact, "_exit_step", per_step)
    fresh = simulate(None, controllers, mission)  # type: ignore[arg-type]
    assert computed  # every exit step went through the per-step path
    for field in dataclasses.fields(reused):
        mine, theirs = getattr(reused, field.name), getattr(fresh, field.name)
        if isinstance(mine, np.ndarray):
            assert mine.tobytes() == theirs.tobytes(), field.name
        else:
            assert mine == theirs, field.name
    if controllers.loop_start is not None:  # the second lap met each cycle step again
        cycle = controllers.steps[controllers.loop_start :]
        exits = [s.step for s in cycle if s.exit_edge is not None and not s.is_vertex]
        assert exits
        assert all(computed.count(step) == 2 for step in exits)


def _numpy_indices(crossing: float, dt: float, count: int) -> list[int]:
    """The definition on numpy's arrays, as the simulation computed it before."""
    steps = exact.SAMPLES_PER_STEP
    wanted = np.rint(np.arange(1, steps) * (np.float64(crossing) / steps) / np.float64(dt))
    return sorted({int(j) for j in wanted.tolist() if 1 <= j <= count})


@given(
    st.floats(1e-12, 1e6, allow_subnormal=False),
    st.floats(1e-12, 1e4, allow_subnormal=False),
    st.integers(0, exact.GRID_POINTS),
)
@example(20.0, 1.0, 128)  # j * 2.5: ties, rounded half to even (2.5 -> 2, 7.5 -> 8)
@example(8.0 * 0.5, 1.0, 128)  # j * 0.5: ties at 0.5 -> 0 (dropped), 1.5 -> 2
def test_sample_indices_are_numpys_rint(crossing: float, dt: float, count: int) -> None:
    assert exact._sample_indices(crossing, dt, count) == _numpy_indices(crossing, dt, count)


def test_sample_indices_round_ties_to_even() -> None:
    # times 2.5, 5, 7.5, 10, 12.5, 15, 17.5 grid steps
    assert exact._sample_indices(20.0, 1.0, 128) == [2, 5, 8, 10, 12, 15, 18]
    assert exact._sample_indices(20.0, 1.0, 10) == [2, 5, 8, 10]  # the last grid point too
    assert exact._sample_indices(20.0, 1.0, 9) == [2, 5, 8]


@pytest.mark.parametrize("name", ["patrol.yaml", "example1.yaml", "deadline.yaml"])
def test_samples_lie_in_their_triangles_and_crossings_in_the_one_entered(name: str) -> None:
    """Barycentric coordinates (an independent computation): every sample lies in the closed
    triangle it is labelled with, and a crossing sample, on the edge between two triangles,
    is labelled with the triangle the trace goes on in (the next sample's)."""
    result = compile_mission(SPECS / name, until="control")
    controllers = result.compilation.get(CONTROLLERS)
    mission = result.compilation.get(MISSION)
    trace = simulate(None, controllers, mission)  # type: ignore[arg-type]
    geometry = result.compilation.get(ABSTRACTION)
    for index, (point, triangle) in enumerate(zip(trace.points, trace.triangles, strict=True)):
        (ax, ay), (bx, by), (cx, cy) = geometry.corners(triangle).tolist()
        x, y = point.tolist()
        area = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
        first = ((bx - x) * (cy - y) - (cx - x) * (by - y)) / area
        second = ((cx - x) * (ay - y) - (ax - x) * (cy - y)) / area
        third = 1.0 - first - second
        assert min(first, second, third) >= -1e-7, (index, triangle)
    # (A crossing followed at once by another belongs to the triangle between the two.)
    crossings = set(trace.crossings)
    followed = [i for i in crossings if i + 1 < len(trace.triangles) and i + 1 not in crossings]
    assert followed
    assert all(trace.triangles[i] == trace.triangles[i + 1] for i in followed)


def test_a_start_on_the_exit_edge_is_the_crossing_into_the_next_triangle() -> None:
    # The first step's sample at time 0 is not taken: the start itself is the crossing, in
    # the triangle the step enters; the next step goes on from there.
    result = compile_mission(SPECS / "patrol.yaml", until="control")
    controllers = result.compilation.get(CONTROLLERS)
    mission = result.compilation.get(MISSION)
    first = controllers.steps[0]
    assert first.exit_edge is not None
    assert first.next_triangle is not None
    corners = np.asarray(first.vertices, dtype=np.float64)
    edge = first.exit_edge
    start = (corners[(edge + 1) % 3] + corners[(edge + 2) % 3]) / 2.0
    on_edge = dataclasses.replace(
        mission, robot=dataclasses.replace(mission.robot, start=tuple(start.tolist()))
    )
    trace = simulate(None, controllers, on_edge)  # type: ignore[arg-type]
    assert trace.crossings[0] == 0
    assert trace.triangles[0] == first.next_triangle
    assert trace.steps[1] == 1  # the next sample is the second step's
    assert trace.triangles[1] == controllers.steps[1].triangle
