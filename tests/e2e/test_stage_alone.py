"""Any stage runs alone from its input artifacts and reproduces what the whole compile wrote."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from tlmpc.io.artifacts import dumps
from tlmpc.io.outdir import write_artifacts
from tlmpc.pipeline.stages import (
    MISSION,
    STAGES,
    MissingProductError,
    compile_mission,
    run_stage_from_artifacts,
    world_of,
)

ROOT = Path(__file__).resolve().parents[2]


def _without_timings(document: Any) -> Any:
    """The document with ``stats`` (timings, solver counters) left out."""
    if isinstance(document, dict):
        return {k: _without_timings(v) for k, v in document.items() if k != "stats"}
    if isinstance(document, list):
        return [_without_timings(v) for v in document]
    return document


#: The plan stage's own refinements of the mesh: then abstraction.json is its mesh, which
#: the abstraction stage alone does not make, and the plan stage alone plans on that mesh
#: (not on the one it refined): both are left out, the later stages compared.
REFINED = ("split_for_u_turns", "split_for_touches", "rings_at_corners", "corridor_refinements")


@pytest.mark.parametrize(
    "spec",
    # a reactive mission whose sensors are not declared by name (mission.json keeps them so)
    ["example1.yaml", "example8.yaml", "patrol.yaml", "deadline.yaml", "reactive/guard.yaml"],
)
def test_every_stage_reproduces_its_artifacts_from_its_inputs(tmp_path: Path, spec: str) -> None:
    whole = compile_mission(ROOT / "specs" / spec, until="verify")
    write_artifacts(tmp_path, whole.artifacts)
    mission = whole.compilation.get(MISSION)
    refined = any(key in whole.artifacts["abstraction.json"]["stats"] for key in REFINED)
    # the verify stage samples a trace again when that makes its certificate hold (the
    # deadline spec's): the simulate stage's own trace.json is the one it wrote before
    simulated = compile_mission(ROOT / "specs" / spec, until="simulate").artifacts
    for stage in STAGES:
        if not stage.requires or stage.name == "plot" or world_of(mission) not in stage.worlds:
            continue
        alone = run_stage_from_artifacts(stage.name, tmp_path)
        if stage.name == "abstraction" and refined:
            assert (
                alone.artifacts["abstraction.json"]["stats"]["triangles"]
                < (whole.artifacts["abstraction.json"]["stats"]["triangles"])
            )
            continue
        if stage.name == "plan" and refined:
            continue
        assert alone.artifacts, stage.name
        wrote = simulated if stage.name == "simulate" else whole.artifacts
        for name, document in alone.artifacts.items():
            expected = json.loads(dumps(wrote[name])) if name.endswith(".json") else wrote[name]
            got = json.loads(dumps(document)) if name.endswith(".json") else document
            assert _without_timings(got) == _without_timings(expected), (stage.name, name)


def _stage(name: str, directory: Path) -> subprocess.CompletedProcess[str]:
    """``tlmpc stage NAME DIR`` in a fresh interpreter."""
    command = [sys.executable, "-m", "tlmpc", "stage", name, str(directory)]
    return subprocess.run(command, capture_output=True, text=True, cwd=ROOT)


def test_a_stage_without_its_inputs_names_the_missing_artifact(tmp_path: Path) -> None:
    whole = compile_mission(ROOT / "specs" / "example1.yaml", until="plan")
    write_artifacts(tmp_path, whole.artifacts)
    (tmp_path / "witness.json").unlink()
    done = _stage("control", tmp_path)
    assert done.returncode == 2
    assert "error[U070]" in done.stderr
    assert "witness.json" in done.stderr
    assert "Traceback" not in done.stderr


def test_a_tampered_input_artifact_is_rejected_by_its_schema(tmp_path: Path) -> None:
    whole = compile_mission(ROOT / "specs" / "example1.yaml", until="control")
    write_artifacts(tmp_path, whole.artifacts)
    controllers = json.loads((tmp_path / "controllers.json").read_text())
    del controllers["steps"][0]["K"]
    (tmp_path / "controllers.json").write_text(json.dumps(controllers))
    done = _stage("simulate", tmp_path)
    assert done.returncode == 2
    assert "controllers.json" in done.stderr
    assert "error[U071]" in done.stderr


def test_a_stage_of_the_other_world_is_refused(tmp_path: Path) -> None:
    whole = compile_mission(ROOT / "specs" / "example1.yaml", until="abstraction")
    write_artifacts(tmp_path, whole.artifacts)
    with pytest.raises(MissingProductError) as caught:
        run_stage_from_artifacts("synthesize", tmp_path)
    assert caught.value.diagnostics[0].code == "U076"
