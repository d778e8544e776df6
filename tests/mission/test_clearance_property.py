"""Every body, margin, convention and map: the path keeps the radius, and summary.json says
what an independent measurement says.

Hypothesis draws a room with rectangular holes, sometimes a second piece of free space
(where the robot may start), a body radius, a margin and the boundary convention.  The
oracle (tests/oracles/clearance.py) measures the compiled trace against the raw rings with
exact segment distances.  Claims checked: the path never comes closer than the radius (to
the verifier's stated 1e-9 of the map's size); ``clearance.obstacles`` in the summary is
that distance minus the radius; R006 is warned exactly when it is below the margin.
"""

from __future__ import annotations

from typing import Any

import pytest
from clearance import inside_free, obstacle_rings, path_clearance
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

import tlmpc
from tlmpc.base.errors import InvalidInputError, NoPlanError


def _rect(x0: float, y0: float, x1: float, y1: float) -> list[tuple[float, float]]:
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


@st.composite
def missions(draw: st.DrawFn) -> tuple[dict[str, Any], list[Any], float, float]:
    holes = []
    for _ in range(draw(st.integers(0, 3))):
        x = draw(st.integers(1, 7))
        y = draw(st.integers(1, 4))
        holes.append(_rect(x, y, x + draw(st.integers(1, 2)), y + draw(st.integers(1, 2))))
    pieces: list[Any] = [(_rect(0, 0, 10, 6), holes)]
    second = draw(st.booleans())
    if second:
        pieces.append((_rect(11, 0, 15, 6), []))
    radius = draw(st.sampled_from([0.0, 0.1, 0.25, 0.4]))
    margin = draw(st.sampled_from([None, 0.0, 0.1, 0.3]))
    in_second = second and draw(st.booleans())
    start = (13.0, 1.0) if in_second else (draw(st.sampled_from([0.5, 1.0, 9.0])), 0.5 + radius)
    goal = [12.0, 4.0, 14.0, 5.5] if in_second else [8.0, 4.5, 9.5, 5.5]
    mission: dict[str, Any] = {
        "version": 1,
        "workspace": {
            "boundary": [list(p) for p in pieces[0][0]],
            "holes": [[list(p) for p in h] for h in holes],
        },
        "regions": {"goal": {"rect": goal}},
        "robot": {"start": list(start), "radius": radius},
        "options": {"boundary": draw(st.sampled_from(["right", "closed"]))},
        "task": ["visit goal"],
    }
    if second:
        mission["workspace"]["components"] = [
            {"boundary": [list(p) for p in pieces[1][0]], "holes": []}
        ]
    if margin is not None:
        mission["options"]["margin"] = margin
    asked = radius if margin is None else margin
    return mission, pieces, radius, asked


@pytest.mark.slow
@settings(
    max_examples=max(10, settings().max_examples // 8),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(missions())
def test_the_path_keeps_the_radius_and_the_summary_measures_it(
    case: tuple[dict[str, Any], list[Any], float, float],
) -> None:
    mission, pieces, radius, margin = case
    start = tuple(mission["robot"]["start"])
    assume(inside_free(start, pieces))
    rings = obstacle_rings(pieces)
    assume(path_clearance([start], rings) >= radius)
    try:
        compiled = tlmpc.compile(mission)
    except (NoPlanError, InvalidInputError):
        event("no plan or refused")
        return  # a goal the body cannot reach, or the start in a hole: not this test's claim
    event("compiled" + (" in the second piece" if start[0] > 10 else ""))
    trace = compiled.artifacts["trace.json"]
    points = [p[1:] for p in trace["points"]]
    measured = path_clearance(points, rings)
    assert measured >= radius - 1e-9 * 15.0
    summary = compiled.summary["clearance"]
    assert summary["obstacles"] == pytest.approx(measured - radius, abs=1e-9)
    warned = any(w.code == "R006" and "obstacle" in w.message for w in compiled.warnings)
    if margin > 0.0 and measured - radius < margin - 1e-9 * max(1.0, margin):
        assert warned
    if warned:
        assert measured - radius < margin


def test_a_start_in_the_second_piece_is_measured_against_its_own_walls() -> None:
    pieces: list[Any] = [(_rect(0, 0, 10, 6), []), (_rect(11, 0, 15, 6), [])]
    mission = {
        "version": 1,
        "workspace": {
            "boundary": [list(p) for p in pieces[0][0]],
            "components": [{"boundary": [list(p) for p in pieces[1][0]], "holes": []}],
        },
        "regions": {"goal": {"rect": [12.0, 4.0, 14.0, 5.5]}},
        "robot": {"start": [13.0, 1.0], "radius": 0.2},
        "options": {"margin": 0.0},
        "task": ["visit goal"],
    }
    compiled = tlmpc.compile(mission)
    points = [p[1:] for p in compiled.artifacts["trace.json"]["points"]]
    measured = path_clearance(points, obstacle_rings(pieces))
    assert measured > 0.2
    assert compiled.summary["clearance"]["obstacles"] == pytest.approx(measured - 0.2, abs=1e-9)
    assert not [w for w in compiled.warnings if w.code == "R006"]
