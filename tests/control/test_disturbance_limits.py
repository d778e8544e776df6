"""What no controller here can do under a disturbance is refused, and the hint is true.

* A plan through a single point (regions touching only at a corner) uses the pursuit law; a
  push across the way to the point turns the robot about it at d / r, so no disturbance is
  rejected there: C034, located at ``robot.disturbance``, and no plan is claimed robust.
* C032's hint: a corner of angle a pushed inside both its facets rejects at most
  max_speed * sin(a / 2) (independent: the largest component of a velocity of norm s along
  two inward normals 180 - a apart).  Where a larger ``min_angle`` is enough, following the
  hint compiles; above the largest ``min_angle`` the hint says none guarantees it, and why.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import tlmpc

ROOT = Path(__file__).resolve().parents[2]


def _corner_mission(disturbance: float) -> dict[str, Any]:
    return {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, 10, 10]}},
        "regions": {"a": {"rect": [2, 2, 5, 5]}, "b": {"rect": [5, 5, 8, 8]}},
        "robot": {"start": [3, 3], "max_speed": 1.0, "disturbance": disturbance},
        "ltl": "G(a | b) & F b",
    }


def test_a_corner_passage_without_disturbance_plans() -> None:
    compiled = tlmpc.compile(_corner_mission(0.0))
    assert compiled.artifacts["witness.json"].get("passages")


@pytest.mark.parametrize("disturbance", [1e-6, 0.1])
def test_a_corner_passage_under_a_disturbance_is_refused_where_it_is(disturbance: float) -> None:
    with pytest.raises(tlmpc.InvalidInputError) as refused:
        tlmpc.compile(_corner_mission(disturbance))
    found = refused.value.diagnostics
    assert [d.code for d in found] == ["C034"]
    assert found[0].path == "$.robot.disturbance"
    assert "(5, 5)" in found[0].message  # the corner the regions share


def _largest_push(angle_degrees: float) -> float:
    """Brute force: the best min over two inward normals of a unit velocity's components."""
    half = math.radians(angle_degrees) / 2.0
    normals = np.array([[math.sin(half), -math.cos(half)], [math.sin(half), math.cos(half)]])
    headings = np.linspace(-math.pi, math.pi, 200_001)
    velocities = np.stack([np.cos(headings), np.sin(headings)], axis=1)
    return float((velocities @ normals.T).min(axis=1).max())


@pytest.mark.parametrize("angle", [20.0, 34.0, 60.0])
def test_the_corner_bound_the_hint_states(angle: float) -> None:
    assert _largest_push(angle) == pytest.approx(math.sin(math.radians(angle) / 2.0), abs=1e-6)


def _example1(disturbance: float, min_angle: float | None = None) -> dict[str, Any]:
    mission = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    mission["robot"]["disturbance"] = disturbance
    if min_angle is not None:
        mission["options"] = {**(mission.get("options") or {}), "min_angle": min_angle}
    return dict(mission)


def _wedge(disturbance: float, min_angle: float | None) -> dict[str, Any]:
    """A 20-degree wedge meshed as it is (no refinement): one triangle is too sharp to stay in."""
    t = math.tan(math.radians(10.0))
    return {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [10, -10 * t], [10, 10 * t]]},
        "regions": {"a": [[6, -0.5], [9, -0.5], [9, 0.5], [6, 0.5]]},
        "robot": {"start": [7.5, 0], "max_speed": 1.0, "disturbance": disturbance},
        "options": {"min_angle": min_angle},
        "task": ["stay in a"],
    }


def test_the_wedge_compiles_on_cells_or_with_the_min_angle_a_corner_needs() -> None:
    """As meshed, the wedge's triangles are too sharp for 0.25: the convex cells carry it; with
    a min_angle whose corners push more than 0.25 (2 asin 0.25, about 29 degrees) the
    triangles do."""
    on_cells = tlmpc.compile(_wedge(0.25, None), until="control")
    assert {s.get("kind") for s in on_cells.artifacts["controllers.json"]["steps"]} == {"cell"}
    needed = math.degrees(2 * math.asin(0.25))
    meshed = tlmpc.compile(_wedge(0.25, math.ceil(needed)), until="control")
    assert all("kind" not in s for s in meshed.artifacts["controllers.json"]["steps"])


def test_above_the_largest_min_angle_the_hint_says_no_min_angle_guarantees_it() -> None:
    with pytest.raises(tlmpc.InvalidInputError) as refused:
        tlmpc.compile(_example1(0.7, min_angle=33), until="control")
    diagnostic = refused.value.diagnostics[0]
    assert diagnostic.code == "C032"
    assert "no options.min_angle guarantees it" in (diagnostic.hint or "")
    ceiling = math.sin(math.radians(34.0) / 2.0)
    assert f"{ceiling:.3f} x max_speed" in (diagnostic.hint or "")
