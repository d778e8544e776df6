"""Vertex passages end to end: the witness and controllers artifacts, the trigger (only when
no plan exists along edges), the pursuit step's bounds, the runtime executor, export-plan.

Oracles: shapely for where regions touch, the plane's geometry for what a plan must do (the
corner point), tests/oracles/trace_check.py for the compiled trajectories.
"""

from __future__ import annotations

import io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
import yaml
from trace_check import check_output

from tlmpc.api import compile as compile_mission
from tlmpc.cli import main
from tlmpc.control.geometry import triangle_geometry
from tlmpc.control.synthesize import _Step, pursuit_controller
from tlmpc.io.schema_check import validation_errors
from tlmpc.planning.io import witness_from_json, witness_to_json
from tlmpc.runtime import Executor, run_closed_loop
from tlmpc.runtime.disturbance import random_disturbance

A = [[2, 2], [5, 2], [5, 5], [2, 5]]
B = [[5, 5], [8, 5], [8, 8], [5, 8]]
CORNER = (5.0, 5.0)


def mission(ltl: str, start: tuple[float, float], boundary: str = "right") -> dict[str, Any]:
    return {
        "version": 1,
        "name": "corner",
        "workspace": {"boundary": [[0, 0], [10, 0], [10, 10], [0, 10]]},
        "regions": {"a": A, "b": B},
        "robot": {"start": list(start), "max_speed": 1.0},
        "ltl": ltl,
        "options": {"boundary": boundary},
    }


def artifacts(document: dict[str, Any]) -> dict[str, Any]:
    return dict(compile_mission(document, until="verify").artifacts)


def test_the_two_regions_touch_only_at_the_corner() -> None:
    touching = shapely.intersection(shapely.Polygon(A), shapely.Polygon(B))
    assert touching.geom_type == "Point"
    assert (touching.x, touching.y) == CORNER


def test_artifacts_of_a_passage_validate_and_round_trip() -> None:
    output = artifacts(mission("G(a | b) & F b", (3, 3)))
    witness = output["witness.json"]
    assert validation_errors(witness, "witness") == []
    assert validation_errors(output["controllers.json"], "controllers") == []
    assert witness["passages"]
    assert witness_to_json(witness_from_json(witness)) == witness
    vertices = output["abstraction.json"]["vertices"]
    (index, vertex), *_ = witness["passages"]
    assert tuple(vertices[vertex]) == CORNER
    step = output["controllers.json"]["steps"][index]
    assert step["kind"] == "vertex"
    assert tuple(step["target"]) == CORNER
    assert step["stay"] is False
    check_output(output, 1.0, 10.0)


def test_plans_along_edges_stay_as_they_were() -> None:
    """A route through the corner is shorter here (from a straight into b), but a plan along
    edges exists (around the corner through free space): vertex passages are not used."""
    output = artifacts(mission("F b", (4.5, 4.5)))
    assert "passages" not in output["witness.json"]
    kinds = {s.get("kind", "affine") for s in output["controllers.json"]["steps"]}
    assert kinds == {"affine"}
    points = [tuple(p[1:]) for p in output["trace.json"]["points"]]
    assert CORNER not in points


def test_the_pursuit_step_reaches_its_corner_within_its_bound() -> None:
    corners = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 4.0]])
    step = _Step(triangle=0, exit_edge=None, next_triangle=1, geometry=triangle_geometry(corners))
    for disturbance in (0.0, 0.25):
        controller = pursuit_controller(0, step, corners[2], 2.0, disturbance)
        # The farthest corner is (3, 0), 5 away; the closing speed is max_speed - d.
        assert controller.exit_time_bound == pytest.approx(5.0 / (2.0 - disturbance))
        assert controller.exit_speed == pytest.approx(2.0 - disturbance)
        speeds = np.linalg.norm(controller.velocities, axis=1)
        assert speeds.tolist() == pytest.approx([2.0, 2.0, 0.0])
        for corner, velocity in zip(corners[:2], controller.velocities[:2], strict=True):
            toward = corners[2] - corner
            cross = toward[0] * velocity[1] - toward[1] * velocity[0]
            assert abs(cross) <= 1e-12
            assert float(toward @ velocity) > 0


def test_the_executor_runs_a_passage_through_the_corner() -> None:
    compiled = compile_mission(mission("G(a | b) & F b", (3, 3)), until="verify")
    executor = Executor.from_output(compiled)
    run = run_closed_loop(executor, random_disturbance(0.0, 0, 1.0), bound=0.0)
    assert run.completed
    assert run.progress.status == "following"
    assert run.recoveries == ()
    points = [tuple(p[1:]) for p in run.trace["points"]]
    closest = min(math.dist(p, CORNER) for p in points)
    assert closest <= 1e-9  # the pursuit lands on the corner, it does not cut it
    assert all(
        shapely.Polygon(A).covers(shapely.Point(p)) or shapely.Polygon(B).covers(shapely.Point(p))
        for p in points
    )


def test_simulate_and_export_plan_keep_the_corner(tmp_path: Path) -> None:
    path = tmp_path / "m.yaml"
    path.write_text(yaml.safe_dump(mission("G(a | b) & F b", (3, 3))))
    out = tmp_path / "out"

    def run(*argv: str) -> tuple[int, str]:
        stdout, stderr = io.StringIO(), io.StringIO()
        return main(list(argv), out=stdout, err=stderr), stdout.getvalue() + stderr.getvalue()

    assert run("compile", str(path), "-o", str(out))[0] == 0
    code, text = run("simulate", str(out), "--disturbance", "0")
    assert code == 0, text
    assert ": satisfied:" in text
    exported = tmp_path / "plan.yaml"
    code, text = run("export-plan", str(out), "--spacing", "100", "-o", str(exported))
    assert code == 0, text
    waypoints = yaml.safe_load(exported.read_text())["waypoints"]
    assert (5.0, 5.0) in [(w["x"], w["y"]) for w in waypoints]
    assert len(waypoints) <= 4  # thinned to the ends, the loop start and the corner


def test_a_tampered_passage_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "m.yaml"
    path.write_text(yaml.safe_dump(mission("G(a | b) & F b", (3, 3))))
    out = tmp_path / "out"
    assert main(["compile", str(path), "-o", str(out)], out=io.StringIO(), err=io.StringIO()) == 0
    witness = json.loads((out / "witness.json").read_text())
    witness["passages"] = [[0, 10**6]]
    (out / "witness.json").write_text(json.dumps(witness))
    from tlmpc.base.errors import UsageError
    from tlmpc.io.artifacts import read_artifacts

    with pytest.raises(UsageError) as caught:
        read_artifacts(out, ("abstraction.json", "witness.json"))
    assert "passage" in caught.value.diagnostics[0].message


def test_the_verifier_reads_the_corner_instant() -> None:
    """Under closed, F(a & b) holds on the compiled trace only at the corner sample: the
    verifier accepts it, and rejects the same trace with that sample moved off the corner
    by a hair (into a alone) — the corner instant's label is what satisfies the task."""
    from tlmpc.verify import verify_document

    output = artifacts(mission("F(a & b)", (1, 1), boundary="closed"))
    trace = output["trace.json"]
    assert verify_document(dict(trace)).satisfied
    index = [tuple(p[1:]) for p in trace["points"]].index(CORNER)
    moved = json.loads(json.dumps(trace))
    moved["points"][index][1:] = [CORNER[0] - 1e-6, CORNER[1] - 1e-6]
    assert shapely.Polygon(B).distance(shapely.Point(moved["points"][index][1:])) > 0
    assert not verify_document(moved).satisfied
