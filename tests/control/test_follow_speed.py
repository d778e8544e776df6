"""The following fields' speed along the path: where a shared vertex velocity would turn a
field off its piece of the path the runs split (tlmpc.control.follow.deflections), and the
floor the following solve rewards is capped, so the robot runs near max_speed.

Oracles: the arc of directions a vertex may take is recomputed by brute force over a fine
grid of unit vectors; the speeds are measured on the trace's exact points (distance over
time between samples, and the affine field's own value there), independently of the
program that chose them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import tlmpc
from tlmpc.control import follow
from tlmpc.control.channel import label_clearance
from tlmpc.control.geometry import triangle_geometry

#: Unit directions every 0.01°: the brute force's grid.
GRID = np.linspace(-math.pi, math.pi, 36_001)


def _allowed(vertices: np.ndarray, local: int, exit_edge: int) -> np.ndarray:
    """By the definition: the grid's directions u with u·n >= 0 across the exit facet and
    u·n <= 0 for the other facets through the vertex (n outward, from the corners alone)."""
    units = np.stack([np.cos(GRID), np.sin(GRID)], axis=1)
    keep = np.ones(len(GRID), dtype=bool)
    for facet in range(3):
        a, b = vertices[(facet + 1) % 3], vertices[(facet + 2) % 3]
        normal = np.array([b[1] - a[1], a[0] - b[0]])  # outward for counter-clockwise corners
        along = units @ normal
        if facet == exit_edge:
            keep &= along >= -1e-9
        elif facet != local:
            keep &= along <= 1e-9
    return keep


@settings(deadline=None, max_examples=150)
@given(
    st.lists(st.floats(-5, 5), min_size=6, max_size=6),
    st.integers(0, 2),
    st.integers(0, 2),
    st.floats(-math.pi, math.pi),
)
def test_a_vertex_arc_and_deviation_match_a_brute_force(
    coords: list[float], exit_edge: int, local: int, direction: float
) -> None:
    corners = np.asarray(coords, dtype=np.float64).reshape(3, 2)
    (ax, ay), (bx, by) = corners[1] - corners[0], corners[2] - corners[0]
    area = float(ax * by - ay * bx)
    longest = max(math.dist(corners[i], corners[i - 1]) for i in range(3))
    if abs(area) < 0.05 * longest**2 or longest < 0.1:
        return  # flat or a needle: the angles are ill-conditioned
    if area < 0:
        corners = corners[::-1].copy()
    geometry = triangle_geometry(corners)
    outward = [math.atan2(ny, nx) - 0.5 * math.pi for nx, ny in geometry.normals.tolist()]
    arc = follow._vertex_arc(outward, local, exit_edge)
    keep = _allowed(corners, local, exit_edge)
    resolution = 2 * math.pi / (len(GRID) - 1)
    if arc is None:
        assert keep.sum() <= 2  # at most the cone's single boundary direction
        return
    start, width = arc
    inside = ((GRID - start) % (2 * math.pi)) <= width
    assert not np.any(inside & ~keep & _clear(GRID, start, width, resolution))
    assert not np.any(keep & ~inside & _clear(GRID, start, width, resolution))
    # the deviation: the angle to the nearest allowed grid direction
    gaps = np.abs((GRID[keep] - direction + math.pi) % (2 * math.pi) - math.pi)
    assert follow._deviation(direction, arc) == pytest.approx(gaps.min(), abs=2 * resolution)


def _clear(angles: np.ndarray, start: float, width: float, margin: float) -> np.ndarray:
    """Grid directions farther than ``margin`` from both ends of the arc."""
    ends = np.array([start, start + width])
    gaps = np.abs((angles[:, None] - ends[None, :] + math.pi) % (2 * math.pi) - math.pi)
    return np.asarray(gaps.min(axis=1) > margin)


@settings(deadline=None, max_examples=150)
@given(
    st.tuples(st.floats(-math.pi, math.pi), st.floats(0.0, math.pi)),
    st.tuples(st.floats(-math.pi, math.pi), st.floats(0.0, math.pi)),
)
def test_two_arcs_intersect_as_a_brute_force_says(
    first: tuple[float, float], second: tuple[float, float]
) -> None:
    def members(arc: tuple[float, float]) -> np.ndarray:
        return np.asarray(((GRID - arc[0]) % (2 * math.pi)) <= arc[1])

    both = members(first) & members(second)
    common = follow._intersect(first, second)
    resolution = 2 * math.pi / (len(GRID) - 1)
    if common is None:
        assert both.sum() <= 2  # touching at an end at most
        return
    inside = members(common)
    for arc in (first, second, common):
        clear = _clear(GRID, *arc, resolution)
        assert not np.any((inside != both) & clear)


def _wall_end(top: float, goal_x: float) -> dict[str, Any]:
    """A room with a wall from the floor up to ``top``; the goal lies beyond it, so the
    shortest way turns round the wall's end (where a shared corner velocity slowed the
    fields to 0.92-0.94 of max_speed on average)."""
    return {
        "version": 1,
        "name": "wall-end",
        "workspace": {
            "boundary": {"rect": [0, 0, 12, 8]},
            "holes": [{"rect": [4, 0, 4.3, top]}],
        },
        "regions": {"goal": {"rect": [goal_x, 1, goal_x + 1.5, 2.5]}},
        "robot": {"start": [1.0, 1.0], "max_speed": 1.0},
        "task": ["visit goal"],
    }


@pytest.mark.parametrize(("top", "goal_x"), [(5.5, 6.0), (6.5, 8.0), (7.0, 6.0)])
def test_the_fields_run_near_max_speed_round_a_walls_end(top: float, goal_x: float) -> None:
    """Until the goal is first entered, the time taken is within 4 % of the distance covered
    at max_speed (chords between the trace's exact points: the curve is no shorter, so the
    mean speed is at least this), and no sample's field exceeds max_speed."""
    compiled = tlmpc.compile(_wall_end(top, goal_x), until="verify")
    assert compiled.summary["verdict"]["satisfied"] is True
    trace = compiled.artifacts["trace.json"]
    controllers = compiled.artifacts["controllers.json"]
    samples = np.asarray(trace["points"], dtype=np.float64)
    goal = shapely.box(goal_x, 1.0, goal_x + 1.5, 2.5)
    met = next(k for k in range(len(samples)) if goal.covers(shapely.Point(samples[k, 1:])))
    chords = np.hypot(*np.diff(samples[: met + 1, 1:], axis=0).T)
    assert samples[met, 0] <= 1.04 * chords.sum() / controllers["max_speed"]
    for (_, x, y), step in zip(samples, trace["steps"], strict=True):
        field = controllers["steps"][step]
        if field.get("kind", "affine") != "affine":
            continue
        velocity = np.asarray(field["K"]) @ np.array([x, y]) + np.asarray(field["g"])
        assert np.hypot(*velocity) <= controllers["max_speed"] * (1.0 + 1e-9)
    jumps = controllers["jumps"]
    assert any(jump["reason"] == follow.DEFLECTS for jump in jumps)


@pytest.mark.parametrize("disturbance", [0.0, 0.02])
@pytest.mark.parametrize("spec", ["example1", "reach-avoid"])
def test_the_weakest_step_keeps_the_vertex_programs_floor_up_to_the_cap(
    spec: str, disturbance: float
) -> None:
    """The smallest guaranteed exit speed of the following fields is at least the vertex
    program's own (solved alone, ``follow=False``) or the cap x max_speed, whichever is
    less (to the solver's tolerance): FLOOR_CAP under a declared disturbance, FREE_FLOOR_CAP
    without one."""
    import dataclasses
    from pathlib import Path

    from tlmpc.control import synthesize
    from tlmpc.pipeline.stages import ABSTRACTION, MISSION, WITNESS, compile_mission

    source = Path(__file__).resolve().parents[2] / "specs" / f"{spec}.yaml"
    compilation = compile_mission(source, until="plan").compilation
    mission, abstraction = compilation.get(MISSION), compilation.get(ABSTRACTION)
    witness = compilation.get(WITNESS)
    robot = dataclasses.replace(mission.robot, disturbance=disturbance)
    followed = synthesize(abstraction, witness, robot)
    alone = synthesize(abstraction, witness, robot, follow=False)
    assert followed.stats["follow_status"] == "Solved"
    fraction = follow.FLOOR_CAP if disturbance > 0.0 else follow.FREE_FLOOR_CAP
    assert follow.floor_cap(disturbance) == fraction
    cap = fraction * mission.robot.max_speed
    floor = min(float(alone.stats["min_exit_speed"]), cap)
    assert float(followed.stats["min_exit_speed"]) >= floor * (1.0 - 1e-5)


@pytest.mark.parametrize("name", ["example8", "example1"])
def test_the_following_solve_rewards_the_floor_up_to_the_cap_only(name: str) -> None:
    """Solved on a shipped plan, the following program's floor variable (the smallest
    guaranteed speed it rewards) is at most the cap of a robot without a disturbance
    (FREE_FLOOR_CAP), while the vertex program alone puts it higher on the same runs (so the
    cap is what holds it); and it reaches the cap (on Example 1's plan, following its path
    would lower the floor were it weighed like the mean guaranteed speed)."""
    from pathlib import Path

    from tlmpc.control.synthesize import (
        _assign_runs,
        conic_form,
        plan_steps,
        vertex_program,
    )
    from tlmpc.pipeline.stages import ABSTRACTION, MISSION, WITNESS, compile_mission

    source = Path(__file__).resolve().parents[2] / "specs" / f"{name}.yaml"
    compilation = compile_mission(source, until="plan").compilation
    mission, abstraction = compilation.get(MISSION), compilation.get(ABSTRACTION)
    steps, loop_start = plan_steps(abstraction, compilation.get(WITNESS))
    guides = follow.path_guides(
        abstraction,
        steps,
        loop_start,
        mission.robot.start,
        clearance=label_clearance(mission.robot.max_speed),
    )
    split = follow.bends(abstraction, steps, loop_start, guides)
    _assign_runs(abstraction, steps, loop_start, split=split)
    steps = [step for step in steps if step.through is None]  # (no vertex passage here)
    program, column = vertex_program(steps, 1.0)
    form = conic_form(program)
    alone = follow._clarabel(form.constraints, form.costs, form.offsets, form.cones)
    assert alone is not None
    floor = 2 * program.runs + program.steps
    assert alone[floor] > follow.FLOOR_CAP + 1e-3
    chosen = [
        follow.FollowStep(
            geometry=step.geometry,
            columns=(column[step.runs[0]], column[step.runs[1]], column[step.runs[2]]),
            guide=guide,
        )
        for step, guide in zip(steps, guides, strict=True)
        if guide is not None and step.exit_edge is not None
    ]
    x = follow._clarabel(
        *follow.follow_program(
            form.constraints,
            form.offsets,
            form.cones,
            program.runs,
            program.steps,
            chosen,
            alignment=follow.ALIGNMENT,
            floor_cap=follow.floor_cap(mission.robot.disturbance),
        )
    )
    assert x is not None
    assert mission.robot.disturbance == 0.0
    assert x[floor] <= follow.FREE_FLOOR_CAP * (1.0 + 1e-6)
    # ... and the floor is worth more than what following gains by lowering it: it reaches
    # the cap (the vertex program alone holds it higher still)
    assert x[floor] >= follow.FREE_FLOOR_CAP * (1.0 - 1e-4)
