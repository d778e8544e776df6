"""The controller re-check knows the disturbance: a field is accepted only if it rejects it.

Fields solved without a disturbance are then re-checked against one: the re-check must flag
exactly the steps whose vertex velocities do not beat the disturbance along every facet they
must cross or stay inside, as computed here from the triangle alone (own facet normals).
Fields solved with the disturbance pass the same re-check.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import tlmpc
from tlmpc.control.io import controllers_from_json
from tlmpc.control.synthesize import violated_condition

ROOT = Path(__file__).resolve().parents[2]


def _normals(vertices: np.ndarray[Any, Any]) -> np.ndarray[Any, Any]:
    """Outward unit normals of facets 0..2 (facet i opposite vertex i), counter-clockwise."""
    normals = np.empty((3, 2))
    for i in range(3):
        a, b = vertices[(i + 1) % 3], vertices[(i + 2) % 3]
        n = np.array([b[1] - a[1], a[0] - b[0]])
        normals[i] = n / np.linalg.norm(n)
    return normals


def _robust_margin(step: Any) -> float:
    """The least push of the step's vertex velocities along what they must do: across the
    exit facet (every vertex), inside each other facet through the vertex."""
    vertices = np.asarray(step.vertices, dtype=float)
    velocities = np.asarray(step.velocities, dtype=float)
    normals = _normals(vertices)
    least = np.inf
    for i in range(3):
        for facet in range(3):
            if facet == i:
                continue
            along = float(normals[facet] @ velocities[i])
            least = min(least, along if facet == step.exit_edge else -along)
    if step.exit_edge is not None:
        least = min(least, float(normals[step.exit_edge] @ velocities[step.exit_edge]))
    return least


def _controllers(disturbance: float) -> Any:
    mission = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    mission["robot"]["disturbance"] = disturbance
    compiled = tlmpc.compile(mission, until="control")
    return controllers_from_json(compiled.artifacts["controllers.json"])


@pytest.mark.parametrize("fraction", [0.1, 0.2, 0.3])
def test_the_recheck_flags_exactly_the_fields_a_disturbance_beats(fraction: float) -> None:
    controllers = _controllers(0.0)
    speed = controllers.max_speed
    disturbance = fraction * speed
    exits = [s for s in controllers.steps if s.exit_edge is not None and s.kind != "vertex"]
    flagged = [violated_condition(s, speed, disturbance) is not None for s in exits]
    expected = [_robust_margin(s) <= disturbance + 1e-9 * speed for s in exits]
    assert flagged == expected
    assert any(expected), "a field solved without a disturbance is beaten by some push"


def test_fields_solved_for_a_disturbance_pass_its_recheck() -> None:
    controllers = _controllers(0.1)
    for step in controllers.steps:
        if step.exit_edge is not None:
            assert _robust_margin(step) > 0.1 * controllers.max_speed
        assert violated_condition(step, controllers.max_speed, 0.1) is None


def _exit_time(step: Any, push: float) -> float | None:
    """RK45: when the step's field plus a steady push of ``push`` straight back against the
    exit facet carries the vertex opposite the exit across it (None if it does not)."""
    from scipy.integrate import solve_ivp

    vertices = np.asarray(step.vertices, dtype=float)
    normal = _normals(vertices)[step.exit_edge]
    level = float(normal @ vertices[(step.exit_edge + 1) % 3])
    gain, offset = np.asarray(step.gain), np.asarray(step.offset)

    def field(t: float, x: np.ndarray[Any, Any]) -> np.ndarray[Any, Any]:
        result: np.ndarray[Any, Any] = gain @ x + offset - push * normal
        return result

    def crossing(t: float, x: np.ndarray[Any, Any]) -> float:
        return float(normal @ x - level)

    crossing.terminal = True  # type: ignore[attr-defined]
    start = vertices[step.exit_edge]  # the vertex opposite the exit: the farthest from it
    horizon = 2.0 * step.exit_time_bound
    run = solve_ivp(field, (0.0, horizon), start, events=crossing, rtol=1e-10, atol=1e-12)
    return float(run.t_events[0][0]) if run.t_events[0].size else None


def test_the_exit_time_bound_holds_under_the_worst_steady_push() -> None:
    """From the vertex farthest from the exit facet, pushed straight back against it at the
    declared bound, the field still leaves before ``exit_time_bound`` (RK45, own geometry);
    the bound is the height over the exit speed less the disturbance."""
    disturbance = 0.1
    controllers = _controllers(disturbance)
    for step in controllers.steps:
        if step.exit_edge is None or step.kind == "vertex":
            continue
        crossed = _exit_time(step, disturbance)
        assert crossed is not None, step.step
        assert crossed <= step.exit_time_bound * (1 + 1e-9), step.step
        vertices = np.asarray(step.vertices, dtype=float)
        normal = _normals(vertices)[step.exit_edge]
        height = float(normal @ (vertices[(step.exit_edge + 1) % 3] - vertices[step.exit_edge]))
        speed = min(float(normal @ w) for w in np.asarray(step.velocities))
        assert step.exit_time_bound == pytest.approx(height / (speed - disturbance), rel=1e-9)


def test_the_stored_gains_keep_the_speed_to_their_rounding_far_from_the_origin() -> None:
    """At 1e8 from the origin: vertex velocities within max_speed (1e-9), K x + g within it
    plus the documented rounding, and the field in the triangle's frame within 1e-9."""
    mission = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    offset = 1e8

    def moved(ring: Any) -> Any:
        return [[x + offset, y + offset] for x, y in ring]

    box = mission["workspace"]["boundary"]["rect"]
    mission["workspace"]["boundary"]["rect"] = [c + offset for c in box]
    for name, shape in mission["regions"].items():
        if isinstance(shape, dict):
            mission["regions"][name] = {"rect": [c + offset for c in shape["rect"]]}
        else:
            mission["regions"][name] = moved(shape)
    mission["robot"]["start"] = [c + offset for c in mission["robot"]["start"]]
    controllers = tlmpc.compile(mission, until="control").artifacts["controllers.json"]
    speed = controllers["max_speed"]
    eps = float(np.finfo(float).eps)
    for step in controllers["steps"]:
        gain, g = np.asarray(step["K"]), np.asarray(step["g"])
        vertices = np.asarray(step["vertices"])
        velocities = np.asarray(step["vertex_velocities"])
        assert np.linalg.norm(velocities, axis=1).max() <= speed * (1 + 1e-9)
        for x, w in zip(vertices, velocities, strict=True):
            rounding = 4 * eps * (np.abs(gain).sum() * np.abs(x).max() + np.abs(g).max())
            assert np.linalg.norm(gain @ x + g) <= speed * (1 + 1e-9) + rounding
            local = velocities[0] + gain @ (x - vertices[0])
            assert np.linalg.norm(local) <= speed * (1 + 1e-9)
            assert np.allclose(local, w, atol=1e-9 * speed)
