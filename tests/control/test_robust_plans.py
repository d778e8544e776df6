"""Disturbances beyond what ``min_angle`` guarantees: plans that keep to corners that reject
them, checked by an independent adversary; and, where the plan cannot, a C032 whose bound is
true on both sides.

* A corner held on both facets rejects at most max_speed * sin(a / 2) and one on the exit edge
  max_speed * cos(a / 2) (brute force over headings here). ``min_angle`` = 34 guarantees
  0.292 x max_speed; the planner keeps to realisable steps, so a mesh with wider corners
  along some route carries more: two equilateral triangles carry 0.45 (a stay in a triangle
  never reaches 0.5: one corner is at most 60 degrees), Example 1 carries 0.35.
* Every step of those plans is run by tests/oracles/adversary.py at the full disturbance,
  pushing out of the nearest guarded facet, against the exit, and along every facet.
* C032 states the bound of the plan it could not realise: the push of its weakest corner,
  recomputed here from that corner's angle; just below it the same mission compiles.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from adversary import check_step

import tlmpc

ROOT = Path(__file__).resolve().parents[2]
HALF = math.sqrt(3.0) / 2.0


def _rhombus(disturbance: float, task: str) -> dict[str, Any]:
    """Two equilateral triangles of side 10 sharing the edge from (0, 0) to (10, 0)."""
    return {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [5, -10 * HALF], [10, 0], [5, 10 * HALF]]},
        "regions": {
            "a": [[0, 0], [5, -10 * HALF], [10, 0]],
            "b": [[0, 0], [10, 0], [5, 10 * HALF]],
        },
        "robot": {"start": [5, -3], "max_speed": 1.0, "disturbance": disturbance},
        # the goal's core adds sharper corners: the goal depth yields to the disturbance (A040)
        "options": {"min_angle": 20},
        "task": [task],
    }


def _example1(disturbance: float) -> dict[str, Any]:
    mission = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    mission["robot"]["disturbance"] = disturbance
    return dict(mission)


def _push(angle: float, kept: bool) -> float:
    """Brute force: the best least component of a unit velocity along a corner's normals."""
    half = angle / 2.0
    if kept:  # inward normals of two facets meeting at the angle
        normals = np.array([[math.sin(half), -math.cos(half)], [math.sin(half), math.cos(half)]])
    else:  # one inward, the other (the exit) outward
        normals = np.array([[math.sin(half), -math.cos(half)], [-math.sin(half), -math.cos(half)]])
    headings = np.linspace(-math.pi, math.pi, 400_001)
    velocities = np.stack([np.cos(headings), np.sin(headings)], axis=1)
    return float((velocities @ normals.T).min(axis=1).max())


@pytest.mark.parametrize("angle", [1.0, 34.0, 60.0, 100.0])
def test_the_corner_pushes_the_planner_uses(angle: float) -> None:
    a = math.radians(angle)
    assert _push(a, kept=True) == pytest.approx(math.sin(a / 2), abs=1e-5)
    assert _push(a, kept=False) == pytest.approx(math.cos(a / 2), abs=1e-5)


@pytest.mark.parametrize(
    ("mission", "disturbance"),
    [(_rhombus, 0.45), (_example1, 0.35)],
)
def test_plans_beyond_the_min_angle_bound_hold_against_the_adversary(
    mission: Any, disturbance: float
) -> None:
    document = mission(disturbance, "visit b") if mission is _rhombus else mission(disturbance)
    compiled = tlmpc.compile(document, until="verify")
    assert compiled.summary["verdict"]["satisfied"] is True
    controllers = compiled.artifacts["controllers.json"]
    assert disturbance > math.sin(math.radians(34.0) / 2.0)
    for step in controllers["steps"]:
        check_step(step, disturbance, controllers["max_speed"])


def test_no_triangle_stay_rejects_half_the_speed() -> None:
    with pytest.raises(tlmpc.InvalidInputError) as refused:
        tlmpc.compile(_rhombus(0.5, "visit b"), until="control")
    diagnostic = refused.value.diagnostics[0]
    assert diagnostic.code == "C032"
    assert "no triangle where the robot stays can reject 0.5" in (diagnostic.hint or "")


def _stated_bound(hint: str) -> tuple[float, tuple[float, float], float]:
    found = re.search(
        r"reject disturbances below ([0-9.e-]+) .*corner \(([0-9.e-]+), ([0-9.e-]+)\) in step "
        r"\d+, angle ([0-9.e-]+) degrees",
        hint,
    )
    assert found is not None, hint
    bound, x, y, angle = (float(found.group(k)) for k in range(1, 5))
    return bound, (x, y), angle


def test_the_c032_bound_is_true_on_both_sides() -> None:
    # (0.7: beyond Example 1's triangles and its convex cells, which carry 0.45)
    with pytest.raises(tlmpc.InvalidInputError) as refused:
        tlmpc.compile(_example1(0.7), until="control")
    diagnostic = refused.value.diagnostics[0]
    assert diagnostic.code == "C032"
    bound, _, angle = _stated_bound(diagnostic.hint or "")
    # the weakest corner is held on both facets (the one C032 names first pushes no more)
    assert bound == pytest.approx(_push(math.radians(angle), kept=True), abs=1e-4)
    assert bound < 0.7
    # just below the stated bound that plan is realisable: the mission compiles and holds
    below = bound * (1 - 1e-3)
    compiled = tlmpc.compile(_example1(below), until="control")
    controllers = compiled.artifacts["controllers.json"]
    for step in controllers["steps"][:4]:
        check_step(step, below, controllers["max_speed"])
