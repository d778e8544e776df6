"""The touch candidate of the ``length`` re-plans (tlmpc.pipeline.touches): a plan on the mesh
split where a plan with U-turns touches a region and turns back.

References: the same compile with the candidate switched off (its path length, the verifier's
verdict), the mesh checked for conformity by the abstraction tests' own checker."""

from __future__ import annotations

from pathlib import Path
from unittest import mock

from tlmpc.pipeline import shortest
from tlmpc.pipeline.stages import MISSION, WITNESS, CompileResult, compile_mission

ROOT = Path(__file__).resolve().parents[2]


def _compiled(*, touches: bool) -> CompileResult:
    """Example 6 with or without the touch candidate (the visit candidate, which runs after
    it and would replace it, left out either way)."""
    spec = str(ROOT / "specs" / "example6.yaml")
    with mock.patch.object(shortest, "visit_touch_candidate", return_value=None):
        if touches:
            return compile_mission(spec)
        with mock.patch.object(shortest, "touch_candidate", return_value=None):
            return compile_mission(spec)


def test_example6_keeps_a_shorter_route_on_a_split_mesh_and_it_verifies() -> None:
    """Example 6 visits six rooms, each goal core two large triangles: the candidate splits
    the cores' edges where the paths touch them, is kept (shorter, not slower), and its trace
    verifies; without the candidate the kept path is longer."""
    result = _compiled(touches=True)
    plain = _compiled(touches=False)
    stats = result.compilation.get(WITNESS).stats
    plain_stats = plain.compilation.get(WITNESS).stats
    assert stats["touch_length"] < plain_stats["path_length"]
    assert stats["path_length"] == stats["touch_length"]
    assert stats["touch_time"] > 0.0
    # the artifacts describe the split mesh the plan was made on
    written = result.artifacts["abstraction.json"]
    assert len(written["triangles"]) > len(plain.artifacts["abstraction.json"]["triangles"])
    assert written["stats"]["split_for_touches"] > 0
    assert result.summary()["verdict"]["satisfied"] is True
    assert result.compilation.get(MISSION).options.cost == "length"


def test_a_plan_without_u_turns_gives_no_candidate() -> None:
    """A mission whose plan with U-turns never turns back (visit one goal and stay there)
    gets no candidate: its witness carries no touch statistics."""
    text = """
version: 1
name: straight
workspace: {boundary: {rect: [0, 0, 6, 3]}}
regions: {goal: {rect: [4.5, 0.5, 5.5, 2.5]}}
robot: {start: [0.5, 1.5], max_speed: 1.0}
task: ["visit goal"]
"""
    result = compile_mission("straight.yaml", text=text)
    stats = result.compilation.get(WITNESS).stats
    assert "touch_length" not in stats


def test_the_patrol_touches_the_goal_its_lap_crossed() -> None:
    """The shipped patrol's lap crossed `charlie`'s core, one triangle, from one base corner
    to the other; split where the lap touches it (the visit candidate), the kept path is
    shorter, its trace verifies, and its lap is nearer the best tour (the independent tour
    oracle) than without the candidate."""
    from test_shortest_route import _lap_over_best_tour

    spec = ROOT / "specs" / "patrol.yaml"
    result = compile_mission(spec)
    with mock.patch.object(shortest, "visit_touch_candidate", return_value=None):
        plain = compile_mission(spec)
    stats = result.compilation.get(WITNESS).stats
    plain_stats = plain.compilation.get(WITNESS).stats
    assert "visit_lengths" not in plain_stats
    assert stats["path_length"] == min(stats["visit_lengths"])
    assert stats["path_length"] < plain_stats["path_length"] * (1.0 - shortest.MIN_GAIN)
    assert result.artifacts["abstraction.json"]["stats"]["split_for_touches"] > 0
    assert result.summary()["verdict"]["satisfied"] is True
    assert _lap_over_best_tour(result) < _lap_over_best_tour(plain) - 0.01


def test_example6s_visits_are_touched_after_its_touch_candidate() -> None:
    """On Example 6 the visit candidate runs on the touch candidate's split mesh, within a
    budget of its own (the rounds before it spent the shared one), and its shorter path is
    kept: the trace verifies."""
    result = compile_mission(str(ROOT / "specs" / "example6.yaml"))
    stats = result.compilation.get(WITNESS).stats
    assert stats["path_length"] == min(stats["visit_lengths"])
    assert stats["path_length"] < stats["touch_length"] * (1.0 - shortest.MIN_GAIN)
    assert result.summary()["verdict"]["satisfied"] is True
