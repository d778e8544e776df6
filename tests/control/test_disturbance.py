"""Controllers reject every additive velocity disturbance up to the mission's bound.

Each compiled step's field plus a disturbance |δ| <= d is integrated by scipy's RK45 from
random states of its triangle, with random, switching and adversarial disturbances (pushing
toward the nearest unplanned facet, or straight against the exit): every run must leave
through the planned facet and never cross another, and every stay must keep the state inside.
The checker uses its own triangle geometry, not tlmpc's.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp

import tlmpc

ROOT = Path(__file__).resolve().parents[2]
Disturbance = Callable[[float, np.ndarray], np.ndarray]


def _facets(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Outward unit normals and offsets of facets 0..2 (facet i opposite vertex i)."""
    normals, offsets = np.empty((3, 2)), np.empty(3)
    for i in range(3):
        a, b = vertices[(i + 1) % 3], vertices[(i + 2) % 3]
        n = np.array([b[1] - a[1], a[0] - b[0]])
        normals[i] = n / np.linalg.norm(n)
        offsets[i] = normals[i] @ a
    return normals, offsets


def _disturbances(
    d: float, normals: np.ndarray, offsets: np.ndarray, exit_edge: int | None, seed: int
) -> list[Disturbance]:
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi)
    constant = d * np.array([np.cos(angle), np.sin(angle)])
    switches = rng.uniform(0, 2 * np.pi, size=64)
    others = [j for j in range(3) if j != exit_edge]

    def steady(t: float, x: np.ndarray) -> np.ndarray:
        return np.asarray(constant)

    def switching(t: float, x: np.ndarray) -> np.ndarray:
        a = switches[int(t * 7.0) % len(switches)]
        return np.asarray(d * np.array([np.cos(a), np.sin(a)]))

    def toward_nearest_wrong_facet(t: float, x: np.ndarray) -> np.ndarray:
        nearest = min(others, key=lambda j: offsets[j] - normals[j] @ x)
        return np.asarray(d * normals[nearest])

    strategies: list[Disturbance] = [steady, switching, toward_nearest_wrong_facet]
    if exit_edge is not None:
        exit_normal = normals[exit_edge]

        def against_the_exit(t: float, x: np.ndarray) -> np.ndarray:
            return np.asarray(-d * exit_normal)

        strategies.append(against_the_exit)
    return strategies


def _facets_crossed(
    gain: np.ndarray,
    offset: np.ndarray,
    normals: np.ndarray,
    offsets: np.ndarray,
    x0: np.ndarray,
    push: Disturbance,
    horizon: float,
) -> list[int]:
    """The facets the disturbed trajectory from ``x0`` crosses first (none when it stays)."""

    def flow(t: float, x: np.ndarray) -> np.ndarray:
        return np.asarray(gain @ x + offset + push(t, x))

    def crossing_of(facet: int) -> Callable[[float, np.ndarray], float]:
        def crossing(t: float, x: np.ndarray) -> float:
            return float(normals[facet] @ x - offsets[facet])

        crossing.terminal = True  # type: ignore[attr-defined]
        crossing.direction = 1  # type: ignore[attr-defined]
        return crossing

    events = [crossing_of(facet) for facet in range(3)]
    run = solve_ivp(flow, (0.0, horizon), x0, events=events, rtol=1e-9, atol=1e-12)
    return [facet for facet in range(3) if len(run.t_events[facet])]


def _compile(disturbance: float) -> dict[str, Any]:
    mission = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    mission["robot"]["disturbance"] = disturbance
    return dict(tlmpc.compile(mission, until="control").artifacts["controllers.json"])


@pytest.mark.parametrize("disturbance", [0.05, 0.15])
def test_every_disturbed_run_follows_the_plan(disturbance: float) -> None:
    controllers = _compile(disturbance)
    rng = np.random.default_rng(7)
    for step in controllers["steps"]:
        vertices = np.asarray(step["vertices"])
        gain, offset = np.asarray(step["K"]), np.asarray(step["g"])
        normals, offsets = _facets(vertices)
        exit_edge = step["exit_edge"]
        size = float(np.ptp(vertices, axis=0).max())
        for strategy in _disturbances(disturbance, normals, offsets, exit_edge, step["step"]):
            x0 = rng.dirichlet(np.ones(3)) @ vertices
            horizon = 50.0 * size / controllers["max_speed"]
            crossed = _facets_crossed(gain, offset, normals, offsets, x0, strategy, horizon)
            if exit_edge is None:
                assert crossed == [], (step["step"], strategy.__name__)
            else:
                assert crossed == [exit_edge], (step["step"], strategy.__name__, crossed)


def test_a_disturbance_no_field_can_reject_is_located() -> None:
    # (0.7: beyond Example 1's triangles, 0.383, and its convex cells, 0.646)
    with pytest.raises(tlmpc.InvalidInputError) as caught:
        _compile(0.7)
    codes = {d.code for d in caught.value.diagnostics}
    assert codes == {"C032"}
    assert all(d.path == "$.robot.disturbance" for d in caught.value.diagnostics)
    with pytest.raises(tlmpc.InvalidInputError) as too_strong:
        _compile(1.0)
    assert too_strong.value.diagnostics[0].code == "C033"


@pytest.mark.parametrize("disturbance", [0.05, 0.15])
def test_the_vertex_programs_own_fields_reject_the_disturbance(disturbance: float) -> None:
    """The vertex program's solution itself meets every vertex condition with the
    disturbance's margin and the speed bound: the re-check after the solve, which rebuilds a
    failing field from its triangle alone, is a safety net, not what makes the fields robust."""
    from tlmpc.control.synthesize import (
        _affine_controller,
        _assign_runs,
        plan_steps,
        run_push,
        solve_vertex_program,
        vertex_program,
        violated_condition,
    )
    from tlmpc.pipeline.stages import ABSTRACTION, MISSION, WITNESS, compile_mission

    document = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    document["robot"]["disturbance"] = disturbance
    built = compile_mission("example1.yaml", text=yaml.safe_dump(document), until="plan")
    mission, abstraction = built.compilation.get(MISSION), built.compilation.get(ABSTRACTION)
    robot = mission.robot
    steps, loop_start = plan_steps(abstraction, built.compilation.get(WITNESS))
    _assign_runs(abstraction, steps, loop_start, push=run_push(robot), max_speed=robot.max_speed)
    affine = [step for step in steps if step.through is None]
    program, column = vertex_program(affine, robot.max_speed, disturbance)
    velocities, _speeds = solve_vertex_program(program)
    for index, step in enumerate(steps):
        if step.through is not None:
            continue
        field = _affine_controller(index, step, velocities[[column[r] for r in step.runs]], robot)
        assert violated_condition(field, robot.max_speed, disturbance) is None, index
