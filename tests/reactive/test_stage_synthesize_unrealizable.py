"""`tlmpc stage synthesize` of an unrealizable mission does what `tlmpc compile` does: exit 1
with Q110, and counterstrategy.json written (the same document compile writes).  The stage
reads mission.json, which has no positions: its diagnostics have no line rather than a
made-up 1:1."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import jsonschema
from reactive_missions import GUARD_UNREALIZABLE

from tlmpc.cli import main
from tlmpc.io.schema_check import load_schema
from tlmpc.mission.io import mission_from_json
from tlmpc.mission.parts import task_parts


def run(*argv: str) -> tuple[int, list[dict[str, Any]]]:
    out = io.StringIO()
    code = main([*argv, "--json"], out=out, err=io.StringIO())
    return code, json.loads(out.getvalue())["diagnostics"]


def test_the_stage_writes_the_counterstrategy_and_places_nothing_falsely(tmp_path: Path) -> None:
    source = tmp_path / "guard.yaml"
    source.write_text(GUARD_UNREALIZABLE)
    whole, staged = tmp_path / "whole", tmp_path / "staged"
    code, compiled = run("compile", str(source), "-o", str(whole))
    assert code == 1
    code, _ = run("compile", str(source), "-o", str(staged), "--until", "abstraction")
    assert code == 0
    assert not (staged / "counterstrategy.json").exists()
    code, found = run("stage", "synthesize", str(staged))
    assert code == 1
    document = json.loads((staged / "counterstrategy.json").read_text())
    jsonschema.validate(document, load_schema("counterstrategy"))
    written = json.loads((whole / "counterstrategy.json").read_text())
    # the same play and core; the core's parts without their places in the YAML
    assert {**document, "core": None} == {**written, "core": None}
    assert [part["text"] for part in document["core"]] == [p["text"] for p in written["core"]]
    assert {(part["line"], part["col"]) for part in document["core"]} == {(None, None)}
    (first,) = [d for d in compiled if d["code"] == "Q110" and d["severity"] == "error"]
    assert (first["line"], first["col"]) == (14, 5)  # the phrase it blames, in the YAML
    (error,) = [d for d in found if d["code"] == "Q110" and d["severity"] == "error"]
    assert error["message"] == first["message"]
    assert error.get("line") is None  # mission.json knows no lines: none rather than 1:1
    assert all(d.get("line") is None for d in found)


def test_the_parts_of_a_mission_read_back_have_no_positions(tmp_path: Path) -> None:
    source = tmp_path / "guard.yaml"
    source.write_text(GUARD_UNREALIZABLE.replace("task:", "ltl: G F home & G !lab\ntask:"))
    out = tmp_path / "out"
    code, _ = run("compile", str(source), "-o", str(out), "--until", "load")
    assert code == 0
    mission = mission_from_json(json.loads((out / "mission.json").read_text()))
    parts = task_parts(mission)
    assert len(parts) == 5  # three phrases, two conjuncts of `ltl`
    assert {(part.line, part.col) for part in parts} == {(None, None)}
