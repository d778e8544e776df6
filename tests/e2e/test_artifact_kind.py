"""An artifact of another kind under an artifact's name is U003 (another ``format``), not a
schema mismatch: the message says which kind was found, whatever the command."""

from __future__ import annotations

import io
import json
import shutil
from pathlib import Path

import pytest

from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.io.artifacts import ARTIFACT_SCHEMAS, read_artifact
from tlmpc.io.outdir import write_artifacts
from tlmpc.pipeline.stages import compile_mission

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("example1")
    write_artifacts(folder, compile_mission(ROOT / "specs" / "example1.yaml").artifacts)
    return folder


def _kinds(folder: Path) -> list[str]:
    return sorted(name for name in ARTIFACT_SCHEMAS if (folder / name).is_file())


def test_every_artifact_of_another_kind_is_u003(compiled: Path, tmp_path: Path) -> None:
    kinds = _kinds(compiled)
    assert len(kinds) >= 6
    for name in kinds:
        other = kinds[(kinds.index(name) + 1) % len(kinds)]
        path = tmp_path / name
        shutil.copyfile(compiled / other, path)
        found = json.loads(path.read_text())["format"]
        with pytest.raises(UsageError) as caught:
            read_artifact(path, ARTIFACT_SCHEMAS[name][1])
        (problem,) = caught.value.diagnostics
        assert problem.code == "U003", (name, other)
        assert found in problem.message


def test_stage_names_the_kind_it_found(compiled: Path, tmp_path: Path) -> None:
    folder = tmp_path / "out"
    shutil.copytree(compiled, folder)
    shutil.copyfile(folder / "verdict.json", folder / "witness.json")
    err = io.StringIO()
    assert main(["stage", "control", str(folder)], io.StringIO(), err) == 2
    assert "error[U003]" in err.getvalue()
    assert "tlmpc.verdict/" in err.getvalue()
