"""The touch candidate of the ``length`` re-plans (tlmpc.pipeline.touches): a plan on the mesh
split where a plan with U-turns touches a region and turns back.

References: the same compile with the candidate switched off (its path length, the verifier's
verdict), the mesh checked for conformity by the abstraction tests' own checker."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any
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


def test_each_split_point_weighs_the_path_of_its_own_visit() -> None:
    """Example 6's visits touch goal cores whose edges lie on common lines (the rooms stand
    in rows): the moves round each split point weigh the path x -> p -> y of the visit that
    split there, not that of another visit whose edge lies on the same line."""
    from tlmpc.pipeline import touches

    meshes: list[Any] = []
    found: list[Any] = []
    weighed: list[tuple[tuple[float, float], Any, Any]] = []
    visit_touches, pieces = touches.visit_touches, touches._pieces

    def recorded_touches(mesh: Any, *rest: Any) -> Any:
        meshes.append(mesh)
        found[:] = visit_touches(mesh, *rest)
        return found

    def recorded_pieces(mesh: Any, vertex: int, x: Any, y: Any) -> Any:
        weighed.append(((float(mesh.vertices[vertex, 0]), float(mesh.vertices[vertex, 1])), x, y))
        return pieces(mesh, vertex, x, y)

    with (
        mock.patch.object(touches, "visit_touches", recorded_touches),
        mock.patch.object(touches, "_pieces", recorded_pieces),
    ):
        compile_mission(str(ROOT / "specs" / "example6.yaml"), until="plan")
    mesh = meshes[-1]

    def split_point(t: int, edge: int, u: float) -> tuple[float, float]:
        corners = mesh.vertices[mesh.triangles[t]]
        a, b = corners[(edge + 1) % 3], corners[(edge + 2) % 3]
        return (float(a[0] + u * (b[0] - a[0])), float(a[1] + u * (b[1] - a[1])))

    points = [split_point(t, edge, u) for t, edge, u, _, _ in found]
    # (split_edges skips a split whose triangles an earlier one cut)
    assert 1 <= len(weighed) <= len(found)
    lines = {round(point[1], 6) for point, _, _ in weighed}
    assert len(lines) < len(weighed)  # two split points on one line at least
    for point, x, y in weighed:
        mine = [k for k, touch in enumerate(found) if (touch[3], touch[4]) == (x, y)]
        assert len(mine) == 1
        assert math.dist(point, points[mine[0]]) < 1e-9
