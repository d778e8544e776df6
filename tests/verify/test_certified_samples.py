"""A compiled trace that satisfies its task but is not certified is sampled again, densely
enough for the certificate: the simulation's own samples stay bit for bit, the ones between
lie on the same exact flow (checked here with scipy's ``expm`` from the sample before, and
a vertex passage's straight line at ``max_speed``), and no gap is longer than asked."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.linalg import expm

from tlmpc.pipeline.stages import CONTROLLERS, MISSION, TRACE, compile_mission
from tlmpc.simulate import simulate

ROOT = Path(__file__).resolve().parents[2]


def rows(trace: Any) -> list[list[float]]:
    table: list[list[float]] = np.column_stack([trace.times, trace.points]).tolist()
    return table


def _is_subsequence(short: list[list[float]], long: list[list[float]]) -> bool:
    found = iter(map(tuple, long))
    return all(any(row == other for other in found) for row in map(tuple, short))


def _on_the_flow(controllers: Any, trace: Any, sparse_times: set[float]) -> None:
    """Every sample not in the sparse trace follows from the sample before it by its step's
    flow (or straight line) over the time between."""
    times, points, steps = trace.times, trace.points, trace.steps
    speed = controllers.max_speed
    checked = 0
    for i in range(1, len(times)):
        if float(times[i]) in sparse_times:
            continue
        step = controllers.steps[steps[i]]
        dt = float(times[i] - times[i - 1])
        before = points[i - 1]
        if step.is_vertex:
            moved = float(np.linalg.norm(points[i] - before))
            assert moved == pytest.approx(dt * speed, rel=1e-9, abs=1e-12)
            towards = np.asarray(step.target) - before
            cross = towards[0] * (points[i] - before)[1] - towards[1] * (points[i] - before)[0]
            assert abs(cross) <= 1e-9 * max(1.0, float(np.linalg.norm(towards)))
        else:
            flow = np.zeros((3, 3))
            flow[:2, :2] = step.gain
            flow[:2, 2] = step.offset
            expected = (expm(dt * flow) @ np.array([*before, 1.0]))[:2]
            assert np.allclose(points[i], expected, rtol=1e-9, atol=1e-9)
        checked += 1
    assert checked


#: Two squares touching at a corner, a point robot held in their union: a vertex passage.
CORNER = """version: 1
name: corner
workspace: {boundary: [[0, 0], [10, 0], [10, 10], [0, 10]]}
regions:
  a: [[2, 2], [5, 2], [5, 5], [2, 5]]
  b: [[5, 5], [8, 5], [8, 8], [5, 8]]
robot: {start: [3, 3], max_speed: 1.0}
ltl: "G(a | b) & F b"
"""


@pytest.mark.parametrize("spec", ["patrol", "example8", "example1", "corner"])
def test_samples_at_most_a_gap_apart_on_the_same_flow(spec: str, tmp_path: Path) -> None:
    if spec == "corner":
        result = compile_mission(tmp_path / "corner.yaml", text=CORNER, until="control")
    else:
        result = compile_mission(ROOT / "specs" / f"{spec}.yaml", until="control")
    controllers = result.compilation.get(CONTROLLERS)
    mission = result.compilation.get(MISSION)
    sparse = simulate(None, controllers, mission)  # type: ignore[arg-type]
    max_gap = 0.05
    dense = simulate(None, controllers, mission, max_gap=max_gap)  # type: ignore[arg-type]
    assert len(dense.times) > len(sparse.times)
    if spec == "corner":
        assert any(step.is_vertex for step in controllers.steps)
    assert _is_subsequence(rows(sparse), rows(dense))
    assert float(np.diff(dense.times).max()) <= max_gap * (1.0 + 1e-9)
    _on_the_flow(controllers, dense, set(sparse.times.tolist()))
    # the crossings are the same samples, and every sample keeps its step's triangle
    assert [dense.times[i] for i in dense.crossings] == [sparse.times[i] for i in sparse.crossings]
    for i, step in enumerate(dense.steps):
        if i and i not in dense.crossings:
            assert dense.triangles[i] == controllers.steps[step].triangle


def test_a_slow_robots_trace_is_sampled_again_and_certified() -> None:
    # Example 7 at 0.3 m/s: its goals are entered 3 cm deep, and the simulation's samples,
    # spaced for the flow, leave the certificate short.
    import yaml

    mission = yaml.safe_load((ROOT / "specs" / "example7.yaml").read_text())
    mission["robot"]["max_speed"] = 0.3
    text = yaml.safe_dump(mission)
    simulated = compile_mission("slow.yaml", text=text, until="simulate")
    verified = compile_mission("slow.yaml", text=text, until="verify")
    sparse = simulated.compilation.get(TRACE)
    dense = verified.compilation.get(TRACE)
    verdict = verified.artifacts["verdict.json"]
    assert verified.artifacts["trace.json"] is dense
    assert verdict["certificate"]["certified"], verdict["certificate"]["reason"]
    assert len(dense["points"]) > len(sparse["points"])
    assert _is_subsequence(sparse["points"], dense["points"])
    max_gap = verdict["robustness"] / (2.0 * dense["max_speed"])
    gaps = np.diff(np.asarray(dense["points"])[:, 0])
    assert float(gaps.max()) <= max_gap * (1.0 + 1e-9)
    # the simulated trace alone was not certified: the resampling is what certifies it
    from tlmpc.verify import verdict_to_json, verify_document

    alone = verdict_to_json(verify_document(dict(sparse)))
    assert alone["satisfied"]
    assert not alone["certificate"]["certified"]


def test_a_certified_trace_is_kept_as_simulated() -> None:
    simulated = compile_mission(ROOT / "specs" / "example1.yaml", until="simulate")
    verified = compile_mission(ROOT / "specs" / "example1.yaml", until="verify")
    assert verified.artifacts["verdict.json"]["certificate"]["certified"]
    assert "samples for the certificate" not in verified.reports[-1].sizes
    assert verified.compilation.get(TRACE)["points"] == simulated.compilation.get(TRACE)["points"]
