"""`tlmpc stage` writes all of its artifacts or none, holds the folder it writes into as
`tlmpc compile` does, and says so when the folder it reads does not exist."""

from __future__ import annotations

import fcntl
import io
import json
import os
from pathlib import Path

import pytest

from tlmpc.cli import main
from tlmpc.io.outdir import write_artifacts
from tlmpc.pipeline.stages import compile_mission

ROOT = Path(__file__).resolve().parents[2]


def _stage(*argv: str) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(["stage", *argv], out, err)
    return code, err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Example 1 compiled up to the plan stage, its formula then edited (so the automaton
    stage writes an automaton.json and an automaton.hoa that both differ from the folder's)."""
    folder = tmp_path_factory.mktemp("example1")
    write_artifacts(
        folder, compile_mission(ROOT / "specs" / "example1.yaml", until="plan").artifacts
    )
    mission = json.loads((folder / "mission.json").read_text())
    mission["formula"] = "G F p2 & G F p3"
    (folder / "mission.json").write_text(json.dumps(mission))
    return folder


def _copy(folder: Path, into: Path) -> Path:
    into.mkdir()
    for entry in folder.iterdir():
        (into / entry.name).write_bytes(entry.read_bytes())
    return into


def test_a_refused_artifact_leaves_the_others_as_they_were(compiled: Path, tmp_path: Path) -> None:
    folder = _copy(compiled, tmp_path / "out")
    before = (folder / "automaton.json").read_bytes()
    (folder / "automaton.hoa").unlink()
    (folder / "automaton.hoa").mkdir()  # the second file cannot be replaced
    code, err = _stage("automaton", str(folder))
    assert code == 2
    assert "error[U034]" in err
    # the first file the stage would write is still the old formula's
    assert (folder / "automaton.json").read_bytes() == before
    assert json.loads(before)["formula"] != "G F p2 & G F p3"
    assert sorted(p.name for p in folder.iterdir() if p.name.startswith(".automaton")) == []


def test_both_artifacts_are_written_when_nothing_is_refused(compiled: Path, tmp_path: Path) -> None:
    folder = _copy(compiled, tmp_path / "out")
    code, err = _stage("automaton", str(folder))
    assert code == 0, err
    assert json.loads((folder / "automaton.json").read_text())["formula"] == "G F p2 & G F p3"
    assert "G F p2 & G F p3" in (folder / "automaton.hoa").read_text()


def test_a_folder_another_run_holds_is_not_written(compiled: Path, tmp_path: Path) -> None:
    folder = _copy(compiled, tmp_path / "out")
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    lock = tmp_path / ".out.tlmpc-lock"  # what `tlmpc compile -o out` holds while it runs
    descriptor = os.open(lock, os.O_RDWR | os.O_CREAT)
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX)
        code, err = _stage("automaton", str(folder))
    finally:
        os.close(descriptor)
    assert code == 2
    assert "error[U032]" in err
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before


def test_the_lock_is_released_after_a_run(compiled: Path, tmp_path: Path) -> None:
    folder = _copy(compiled, tmp_path / "out")
    assert _stage("automaton", str(folder))[0] == 0
    assert not (tmp_path / ".out.tlmpc-lock").exists()
    assert _stage("automaton", str(folder))[0] == 0


def test_a_missing_input_folder_is_not_a_compile_output(tmp_path: Path) -> None:
    code, err = _stage("verify", str(tmp_path / "missing"))
    assert code == 2
    assert "error[U020]" in err
    assert "create it first" not in err


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Example 1 compiled through the control stage, unedited."""
    folder = tmp_path_factory.mktemp("planned")
    result = compile_mission(ROOT / "specs" / "example1.yaml", until="control")
    write_artifacts(folder, result.artifacts)
    return folder


#: Values of mission.json the mission format refuses, each of which reached the
#: triangulation or the controllers' solver (exit 3) before.
OUT_OF_RANGE = [
    (("options", "max_area"), 0.0),
    (("options", "min_angle"), 60.0),
    (("options", "margin"), 1e308),
    (("robot", "radius"), 1e308),
    (("robot", "max_speed"), 1e300),
    (("workspace", "boundary"), [[0, 0], [1e300, 0], [1e300, 1e300], [0, 1e300]]),
]


def _edited(folder: Path, into: Path, keys: tuple[str, ...], value: object) -> Path:
    copy = _copy(folder, into)
    mission = json.loads((copy / "mission.json").read_text())
    parent = mission
    for key in keys[:-1]:
        parent = parent[key]
    parent[keys[-1]] = value
    (copy / "mission.json").write_text(json.dumps(mission))
    return copy


@pytest.mark.parametrize(("keys", "value"), OUT_OF_RANGE)
@pytest.mark.parametrize("stage", ["abstraction", "control"])
def test_a_mission_value_out_of_range_is_refused_by_its_schema(
    planned: Path, tmp_path: Path, keys: tuple[str, ...], value: object, stage: str
) -> None:
    folder = _edited(planned, tmp_path / "out", keys, value)
    code, err = _stage(stage, str(folder))
    assert code == 2, err
    assert "error[U071]" in err
    assert f"$.{keys[0]}" in err


def test_shapes_no_mission_holds_are_refused_at_their_json_path(
    planned: Path, tmp_path: Path
) -> None:
    from shapely.geometry import Polygon

    bow_tie = [[0.5, 0.5], [3.0, 0.5], [0.5, 3.0], [3.0, 3.0]]
    assert not Polygon(bow_tie).is_valid  # the oracle: not a simple polygon
    folder = _edited(planned, tmp_path / "bow", ("regions", "p1"), bow_tie)
    code, err = _stage("abstraction", str(folder))
    assert code == 2
    assert "error[U042]" in err
    assert "region 'p1'" in err

    outside = [[50.0, 50.0], [51.0, 50.0], [51.0, 51.0]]
    boundary = json.loads((planned / "mission.json").read_text())["workspace"]["boundary"]
    assert not Polygon(boundary).covers(Polygon(outside))
    folder = _edited(planned, tmp_path / "outside", ("regions", "p1"), outside)
    code, err = _stage("abstraction", str(folder))
    assert code == 2
    assert "error[U042]" in err
    assert "outside the workspace" in err


def test_an_unedited_mission_passes_the_shape_checks(planned: Path, tmp_path: Path) -> None:
    folder = _copy(planned, tmp_path / "out")
    code, err = _stage("abstraction", str(folder))
    assert code == 0, err
