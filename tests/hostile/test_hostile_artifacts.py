"""Edited artifacts: one value anywhere in one artifact replaced by a hostile one, then every
command that reads artifacts run on the folder.  Each run answers (0/1/2/4) with a located
diagnostic when it refuses, never a crash, and writes nothing but its own output."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from typing import Any

import pytest
from hostile_harness import (  # noqa: F401 (fixtures, found by their names)
    compiled_fixture,
    compiled_once_fixture,
    run_hostile,
    work_fixture,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

ARTIFACTS = ("mission.json", "abstraction.json", "witness.json", "controllers.json", "trace.json")
HOSTILE_VALUES: list[Any] = [
    math.nan,
    math.inf,
    -math.inf,
    1e300,
    -1,
    10**9,
    2**70,
    0,
    "x",
    "",
    None,
    True,
    [],
    {},
    [[0.0, 0.0]],
]
COMMANDS: list[tuple[str, ...]] = [
    ("view", "out", "-o", "page.html"),
    ("export-plan", "out", "--format", "geojson", "-o", "plan.geojson"),
    ("export-plan", "out", "--format", "path-mcap", "-o", "plan.mcap"),
    ("export", "out", "-o", "model.pml"),
    ("stage", "simulate", "out", "-o", "stage"),
    ("stage", "verify", "out", "-o", "stage"),
    ("simulate", "out", "--cycles", "1", "-o", "trace.json"),
]
#: The artifacts each command reads (from the commands' documentation).
READS = {
    "view": {"mission.json", "abstraction.json", "trace.json"},
    "export-plan": {"mission.json", "trace.json", "controllers.json"},
    "export": {"mission.json", "abstraction.json"},
    "simulate": {
        "mission.json",
        "abstraction.json",
        "automaton.json",
        "witness.json",
        "controllers.json",
    },
    ("stage", "simulate"): {"mission.json", "abstraction.json", "controllers.json"},
    ("stage", "verify"): {"trace.json"},
}


def _reads(command: tuple[str, ...]) -> set[str]:
    return READS[(command[0], command[1])] if command[0] == "stage" else READS[command[0]]


def _leaves(value: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every path to a value of ``value`` (containers included), long lists sampled."""
    found = [path]
    if isinstance(value, dict):
        for key in sorted(value):
            found.extend(_leaves(value[key], (*path, key)))
    elif isinstance(value, list):
        step = max(1, len(value) // 4)
        for index in range(0, len(value), step):
            found.extend(_leaves(value[index], (*path, index)))
    return found


def _replace(document: Any, path: tuple[Any, ...], new: Any) -> Any:
    if not path:
        return new
    parent = document
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = new
    return document


@pytest.mark.slow
@settings(
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_an_edited_artifact_is_refused_or_answered(
    compiled_once: Path, work: Path, data: st.DataObject
) -> None:
    # a fresh copy per example (the fixtures are shared by the examples)
    for entry in work.iterdir():
        shutil.rmtree(entry) if entry.is_dir() else entry.unlink()
    compiled = work / "out"
    shutil.copytree(compiled_once, compiled)
    name = data.draw(st.sampled_from(ARTIFACTS), label="artifact")
    path = compiled / name
    document = json.loads(path.read_text())
    where = data.draw(st.sampled_from(_leaves(document)[1:]), label="path")
    new = data.draw(st.sampled_from(HOSTILE_VALUES), label="value")
    path.write_text(json.dumps(_replace(document, where, new)))
    (work / "stage").mkdir(exist_ok=True)
    (work / "stage" / ".tlmpc-output").write_text("tlmpc.io.outdir/1\n")
    command = data.draw(st.sampled_from(COMMANDS), label="command")
    outputs = ["page.html", "plan.geojson", "plan.mcap", "model.pml", "stage", "trace.json"]
    result = run_hostile(work, *command, may_write=outputs)
    if isinstance(new, float) and not math.isfinite(new) and name in _reads(command):
        # a non-finite number never passes: refused where it is read
        assert result.code == 2, result.err
        assert "U002" in result.codes(), result.err


@pytest.mark.parametrize("command", COMMANDS)
def test_nan_never_passes_an_artifact_check(
    compiled: Path, work: Path, command: tuple[str, ...]
) -> None:
    path = compiled / "controllers.json"
    document = json.loads(path.read_text())
    document["max_speed"] = math.nan
    path.write_text(json.dumps(document))
    trace = compiled / "trace.json"
    document = json.loads(trace.read_text())
    document["points"][1][1] = math.nan
    trace.write_text(json.dumps(document))
    (work / "stage").mkdir()
    outputs = ["stage", "page.html", "plan.geojson", "plan.mcap", "model.pml", "trace.json"]
    result = run_hostile(work, *command, may_write=outputs)
    if command[0] == "export":  # reads neither file: answers
        assert result.code == 0, result.err
        return
    assert result.code == 2, result.err
    assert result.codes()[0] in ("U002", "U041"), result.err


def test_artifacts_of_two_missions_are_refused(compiled: Path, work: Path) -> None:
    trace = compiled / "trace.json"
    document = json.loads(trace.read_text())
    document["regions"] = {"elsewhere": [[0, 0], [1, 0], [1, 1]]}
    trace.write_text(json.dumps(document))
    for command in (("view", "out", "-o", "page.html"), ("export-plan", "out")):
        result = run_hostile(work, *command, may_write=["page.html"])
        assert result.code == 2
        assert result.codes() == ["U042"]


def test_controllers_of_another_plan_are_refused(compiled: Path, work: Path) -> None:
    path = compiled / "controllers.json"
    document = json.loads(path.read_text())
    document["steps"] = document["steps"][:-1]
    path.write_text(json.dumps(document))
    for command in (("simulate", "out"), ("stage", "simulate", "out")):
        result = run_hostile(work, *command)
        assert result.code == 2
        assert result.codes() == ["U042"]
