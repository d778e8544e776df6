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
from tlmpc.control.synthesize import _violated_condition

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


@pytest.mark.parametrize("fraction", [0.05, 0.1, 0.2])
def test_the_recheck_flags_exactly_the_fields_a_disturbance_beats(fraction: float) -> None:
    controllers = _controllers(0.0)
    speed = controllers.max_speed
    disturbance = fraction * speed
    exits = [s for s in controllers.steps if s.exit_edge is not None and s.kind != "vertex"]
    flagged = [_violated_condition(s, speed, disturbance) is not None for s in exits]
    expected = [_robust_margin(s) <= disturbance + 1e-9 * speed for s in exits]
    assert flagged == expected
    assert any(expected), "a field solved without a disturbance is beaten by some push"


def test_fields_solved_for_a_disturbance_pass_its_recheck() -> None:
    controllers = _controllers(0.1)
    for step in controllers.steps:
        if step.exit_edge is not None:
            assert _robust_margin(step) > 0.1 * controllers.max_speed
        assert _violated_condition(step, controllers.max_speed, 0.1) is None
