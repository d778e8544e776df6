"""The largest disturbance any plan on a mesh rejects (the widest-lasso search), and the goal
depth yielding to the disturbance.

* tests/oracles/brute_bottleneck.py builds the product from the mesh arrays, computes every
  step's width from arccos angles and tries every width as a floor with plain depth-first
  searches (no bisection, no components): the search's value is the largest floor with a
  lasso, on small random missions.
* The value is the planner's own threshold: restricted to the steps the controllers realise
  under d, the planner finds a plan for d just below it and none at it.
* Example 1 under a disturbance: C032 states the bound, the mission compiles just below it;
  with the default goal depth it compiles wherever it does with ``goal_depth: 0``, warning
  A040 when the goal cores had to yield.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest
import yaml
from adversary import check_step
from brute_bottleneck import widest_lasso
from hypothesis import event, example, given, settings
from hypothesis import strategies as st
from small_maps import RECTS, TASKS, small_mission

import tlmpc
from tlmpc.abstraction import build_abstraction
from tlmpc.automata import translate
from tlmpc.automata.degeneralize import degeneralize
from tlmpc.automata.model import Automaton, Edge
from tlmpc.base.errors import InvalidInputError, NoPlanError
from tlmpc.ltl.ast import Const, Not, Prop
from tlmpc.mission import load_mission_text
from tlmpc.planning.bottleneck import supported_ratio
from tlmpc.planning.plan import plan
from tlmpc.planning.robust import TOLERANCE, witness_realisable

ROOT = Path(__file__).resolve().parents[2]


@settings(max_examples=max(20, settings().max_examples // 2), deadline=None)
@given(
    st.sampled_from(TASKS),
    st.lists(RECTS, min_size=3, max_size=3),
    st.sampled_from([(5.5, 4.5), (3.0, 2.5), (0.5, 0.5), (5.9, 0.1), (1.0, 4.0)]),
)
# Two regions sharing an edge, a patrol between them.
@example("patrol a, b", [(0, 0, 2, 2), (2, 0, 2, 2), (4, 3, 1, 1)], (3.0, 2.5))
# The start's own triangle is the bottleneck: wide cycles elsewhere are not reached above it.
@example("visit a", [(1, 3, 1, 2), (4, 0, 2, 3), (3, 0, 1, 1)], (5.9, 0.1))
# Overlapping regions: the patrol's automaton cycles while the robot stays in the overlap
# (a stay, which needs the triangle's stay width, not a moving cycle).
@example("patrol a, b", [(0, 0, 3, 3), (1, 1, 3, 3), (4, 3, 1, 1)], (5.5, 4.5))
def test_the_widest_lasso_is_the_brute_force_maximum(
    task: str, regions: list[tuple[int, int, int, int]], start: tuple[float, float]
) -> None:
    try:
        mission = load_mission_text(small_mission(task, regions, start), "m.yaml")
    except InvalidInputError:
        event("invalid map")
        return
    mesh = build_abstraction(mission)
    automaton = translate(mission.formula, letters=mesh.letters)
    found = supported_ratio(
        mesh,
        automaton,
        formula=mission.formula,
        options=mission.options,
        start_point=mission.robot.start,
    )
    model = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    expected = widest_lasso(mesh, model, mission.robot.start)
    if expected is None:
        event("no lasso")
        assert found is None
        return
    event("lasso")
    assert found is not None
    assert found == pytest.approx(expected, abs=1e-12)
    # The planner's own threshold: a plan on the realisable steps just below, none at it.
    planned = plan(
        mesh,
        automaton,
        formula=mission.formula,
        options=mission.options,
        start_point=mission.robot.start,
        reject=found - 3 * TOLERANCE,
    )
    assert witness_realisable(mesh, planned, found - 3 * TOLERANCE)
    with pytest.raises(NoPlanError):
        plan(
            mesh,
            automaton,
            formula=mission.formula,
            options=mission.options,
            start_point=mission.robot.start,
            reject=found - 0.5 * TOLERANCE,
        )


def _example1(disturbance: float, **options: Any) -> dict[str, Any]:
    mission = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    mission["robot"]["disturbance"] = disturbance
    mission["options"] = options
    return dict(mission)


def _stated(hint: str) -> float:
    found = re.search(r"the largest disturbance any plan on this mesh rejects is ([0-9.e-]+)", hint)
    assert found is not None, hint
    return float(found.group(1))


def test_c032_states_the_largest_disturbance_the_mesh_supports() -> None:
    # (0.7: beyond Example 1's triangles and its convex cells, which carry 0.45)
    with pytest.raises(tlmpc.InvalidInputError) as refused:
        tlmpc.compile(_example1(0.7), until="control")
    diagnostic = refused.value.diagnostics[0]
    assert diagnostic.code == "C032"
    assert diagnostic.path == "$.robot.disturbance"
    stated = _stated(diagnostic.hint or "")
    # above what min_angle can promise (sin 17 degrees), below what was asked
    assert 0.292 < stated < 0.45
    # just below it the mission compiles, and every step holds against the adversary
    below = stated * (1 - 1e-5)
    compiled = tlmpc.compile(_example1(below), until="control")
    controllers = compiled.artifacts["controllers.json"]
    for step in controllers["steps"]:
        check_step(step, below, controllers["max_speed"])
    assert all("kind" not in s for s in controllers["steps"])  # on triangles
    # just above it (the printed value's rounding aside) no plan on triangles does: the
    # plan stage's last rung, convex cells, carries it
    above = tlmpc.compile(_example1(stated * (1 + 1e-5)), until="control")
    assert {s.get("kind") for s in above.artifacts["controllers.json"]["steps"]} == {"cell"}


def test_the_goal_depth_yields_to_the_disturbance() -> None:
    # Example 1 at 0.37 compiled before goal cores existed; their corners are sharper
    compiled = tlmpc.compile(_example1(0.37), until="control")
    warnings = [w for w in compiled.warnings if w.code == "A040"]
    assert len(warnings) == 1
    assert warnings[0].severity == "warning"
    assert warnings[0].path == "$.robot.disturbance"
    assert "0.37" in warnings[0].message
    # half the goal depth is enough there
    assert "with cores 0.5 x the goal depth deep" in warnings[0].message
    # at 0.38 only the regions as drawn carry it (a 45 degree corner: sin 22.5 = 0.3827)
    drawn = tlmpc.compile(_example1(0.38), until="control")
    (warning,) = [w for w in drawn.warnings if w.code == "A040"]
    assert "only as deep as the margin asks" in warning.message
    controllers = compiled.artifacts["controllers.json"]
    for step in controllers["steps"]:
        check_step(step, 0.37, controllers["max_speed"])
    # an explicit goal depth is named as the cause
    explicit = tlmpc.compile(_example1(0.37, goal_depth=0.5), until="control")
    assert [w.path for w in explicit.warnings if w.code == "A040"] == ["$.options.goal_depth"]
    # where the goal cores' plan holds, nothing yields and nothing is said
    calm = tlmpc.compile(_example1(0.3), until="control")
    assert not [w for w in calm.warnings if w.code == "A040"]


def _random_mission(
    task: str, regions: list[tuple[int, int, int, int]], ratio: float, goal_depth: float | None
) -> dict[str, Any]:
    return {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, 8, 6]}},
        "regions": {
            name: {"rect": [x0, y0, x0 + w, y0 + h]}
            for name, (x0, y0, w, h) in zip("abc", regions, strict=True)
        },
        "robot": {"start": [7.5, 5.5], "max_speed": 2.0, "disturbance": 2.0 * ratio},
        "task": [task],
        "options": {} if goal_depth is None else {"goal_depth": goal_depth},
    }


@pytest.mark.slow
@settings(max_examples=max(8, settings().max_examples // 4), deadline=None)
@given(
    st.sampled_from(TASKS),
    st.lists(
        st.tuples(st.integers(0, 5), st.integers(0, 3), st.integers(1, 3), st.integers(1, 3)),
        min_size=3,
        max_size=3,
    ),
    st.floats(0.05, 0.45),
    st.sampled_from([None, 0.2, 1.0]),
)
# Example-1-like: goal cores whose corners are sharper than the regions' own.
@example("visit a then b", [(0, 0, 3, 3), (5, 3, 3, 3), (3, 0, 1, 1)], 0.35, None)
# No plan reaches the goal depth at all (b's core lies inside c): the plan entering b only as
# deep as the margin asks must carry the disturbance too (on cells, as at goal depth 0).
@example("avoid c until b", [(0, 0, 1, 1)] * 3, 0.25, None)
def test_a_mission_compiles_under_disturbance_whenever_it_does_at_goal_depth_zero(
    task: str, regions: list[tuple[int, int, int, int]], ratio: float, depth: float | None
) -> None:
    try:
        tlmpc.compile(_random_mission(task, regions, ratio, 0.0), until="control")
    except tlmpc.TlmpcError as refused:
        event(f"refused at depth 0 ({refused.diagnostics[0].code})")
        return
    compiled = tlmpc.compile(_random_mission(task, regions, ratio, depth), until="control")
    event("yielded" if any(w.code == "A040" for w in compiled.warnings) else "kept the depth")


def _two_beat() -> Automaton:
    """``G F b`` read in two beats: b takes state 0 to 1 and 1 back to 0 with the mark, and
    no state keeps b on a self-loop; a robot that stays in ``b`` is accepted by the cycle
    0 -> 1 -> 0 of stutter steps, with no accepting stutter loop to show it."""
    b = Prop("b")
    return Automaton(
        aps=("b",),
        num_states=2,
        initial=0,
        edges=(
            Edge(src=0, dst=1, guard=b),
            Edge(src=1, dst=0, guard=b, marks=frozenset({0})),
            Edge(src=0, dst=0, guard=Not(b)),
            Edge(src=1, dst=1, guard=Not(b)),
        ),
        num_acc=1,
    )


@pytest.mark.parametrize("start", [(0.5, 0.5), (3.0, 2.5), (5.5, 4.5)])
def test_a_cycle_of_stutter_steps_is_a_stay(start: tuple[float, float]) -> None:
    text = small_mission("visit b", [(4, 3, 1, 1), (0, 0, 3, 2), (5, 0, 1, 1)], start)
    mission = load_mission_text(text, "m.yaml")
    mesh = build_abstraction(mission)
    automaton = _two_beat()
    found = supported_ratio(
        mesh,
        automaton,
        formula=Const(True),
        options=mission.options,
        start_point=mission.robot.start,
    )
    assert found == pytest.approx(widest_lasso(mesh, automaton, start), abs=1e-12)
