"""Artifacts read back from an output folder are refused (U042, U002) when they could not
have been written by tlmpc: an automaton whose edges name missing states, a mesh whose
neighbours do not share their edges, a number that overflows to infinity however it is
written.  Never an exit 3 or a bare exception from the stage that would use them."""

from __future__ import annotations

import io
import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import tlmpc
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


def _edited(folder: Path, into: Path, name: str, edit: Callable[[dict[str, Any]], None]) -> Path:
    into.mkdir()
    for entry in folder.iterdir():
        (into / entry.name).write_bytes(entry.read_bytes())
    document = json.loads((into / name).read_text())
    edit(document)
    (into / name).write_text(json.dumps(document))
    return into


def _run(*argv: str) -> tuple[int, str]:
    err = io.StringIO()
    return main(list(argv), io.StringIO(), err), err.getvalue()


def _edge_source(value: Any) -> Callable[[dict[str, Any]], None]:
    def edit(automaton: dict[str, Any]) -> None:
        automaton["edges"][0]["src"] = len(automaton["states"]) if value is None else value

    return edit


@pytest.mark.parametrize("value", [None, 1e308, -1])
def test_an_edge_to_no_state_is_refused(compiled: Path, tmp_path: Path, value: Any) -> None:
    folder = _edited(compiled, tmp_path / "out", "automaton.json", _edge_source(value))
    for argv in (
        ("stage", "plan", str(folder), "-o", str(tmp_path)),
        ("simulate", str(folder), "--cycles", "1", "-o", str(tmp_path / "sim.json")),
    ):
        code, err = _run(*argv)
        assert code == 2, err
        assert f"{folder / 'automaton.json'}: error[" in err
    with pytest.raises(tlmpc.UsageError):
        tlmpc.executor(folder)


def _shares_edges(abstraction: dict[str, Any]) -> bool:
    """The oracle: every neighbour shares the edge opposite the vertex it stands for."""
    triangles = abstraction["triangles"]
    for t, row in enumerate(abstraction["neighbors"]):
        for corner, u in enumerate(row):
            if u < 0:
                continue
            edge = {triangles[t][(corner + 1) % 3], triangles[t][(corner + 2) % 3]}
            if not edge <= set(triangles[u]) or t not in abstraction["neighbors"][u]:
                return False
    return True


def _swap_neighbours(abstraction: dict[str, Any]) -> None:
    row = abstraction["neighbors"][2]
    row[0], row[1] = row[1], row[0]


def _clockwise(abstraction: dict[str, Any]) -> None:
    triangle, row = abstraction["triangles"][5], abstraction["neighbors"][5]
    triangle[1], triangle[2] = triangle[2], triangle[1]
    row[1], row[2] = row[2], row[1]


def test_the_compiled_mesh_is_one_mesh(compiled: Path) -> None:
    assert _shares_edges(json.loads((compiled / "abstraction.json").read_text()))


@pytest.mark.parametrize("edit", [_swap_neighbours, _clockwise])
def test_a_mesh_that_contradicts_itself_is_refused(
    compiled: Path, tmp_path: Path, edit: Callable[[dict[str, Any]], None]
) -> None:
    folder = _edited(compiled, tmp_path / "out", "abstraction.json", edit)
    abstraction = json.loads((folder / "abstraction.json").read_text())
    vertices = np.array(abstraction["vertices"])
    a, b, c = (vertices[abstraction["triangles"][5][k]] for k in range(3))
    counter_clockwise = (b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0] > 0
    assert not (_shares_edges(abstraction) and counter_clockwise)  # the oracle: edited
    for stage in ("control", "simulate"):
        code, err = _run("stage", stage, str(folder), "-o", str(tmp_path))
        assert code == 2, err
        assert f"{folder / 'abstraction.json'}: error[U042]" in err


@pytest.mark.parametrize("digits", ["1" + "0" * 400 + ".0", "1E+309"])
def test_a_number_that_overflows_is_u002_where_it_is(
    compiled: Path, tmp_path: Path, digits: str
) -> None:
    folder = tmp_path / "out"
    _edited(compiled, folder, "mission.json", lambda mission: None)
    written = (folder / "mission.json").read_text()
    text = written.replace('"max_speed": 1.0', f'"max_speed": {digits}')
    assert digits in text
    (folder / "mission.json").write_text(text)
    place = text.index(digits)
    line, col = text.count("\n", 0, place) + 1, place - text.rfind("\n", 0, place)
    code, err = _run("stage", "control", str(folder), "-o", str(tmp_path))
    assert code == 2, err
    assert f"{folder / 'mission.json'}:{line}:{col}: error[U002]" in err
    assert "hint:" in err


# Another kind of artifact under an artifact's name is U003 (another ``format``), not a schema
# mismatch: the message says which kind was found, whatever the command.
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
