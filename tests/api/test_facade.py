"""The Python facade: a mission as a dict, YAML text or path; outputs read back; typed errors."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml

import tlmpc

ROOT = Path(__file__).resolve().parents[2]


def _mission() -> dict[str, Any]:
    return {
        "version": 1,
        "name": "notebook",
        "workspace": {"boundary": {"rect": [0, 0, 10, 6]}, "holes": [{"rect": [4, 2, 6, 4]}]},
        "regions": {"dock": {"rect": [8, 4, 9.5, 5.5]}, "home": {"rect": [0.5, 0.5, 2, 2]}},
        "robot": {"start": [1, 1], "max_speed": 1.0},
        "task": ["visit dock then return to home"],
    }


def test_notebook_style_compile_and_verify_a_dict_mission(tmp_path: Path) -> None:
    result = tlmpc.compile(_mission())
    assert result.formula == "F(dock & F home)"
    assert result.plan is not None
    assert result.summary["verdict"]["satisfied"] is True
    verdict = tlmpc.verify_trace(result)
    assert verdict.satisfied
    # The trajectory really reaches the dock and ends in home (checked on the samples directly).
    points = result.trajectory
    assert any(8 <= x <= 9.5 and 4 <= y <= 5.5 for _, x, y in points)
    _, x_end, y_end = points[-1]
    assert 0.5 <= x_end <= 2
    assert 0.5 <= y_end <= 2
    # Written and read back, the same artifacts.
    out = result.write(tmp_path / "out")
    again = tlmpc.read_output(out)
    assert again.artifacts["witness.json"] == result.artifacts["witness.json"]
    assert tlmpc.verify_trace(out / "trace.json").satisfied


def test_yaml_text_and_path_give_the_same_plan(tmp_path: Path) -> None:
    text = yaml.safe_dump(_mission())
    path = tmp_path / "m.yaml"
    path.write_text(text, encoding="utf-8")
    from_text = tlmpc.compile(text, until="plan")
    from_path = tlmpc.compile(path, until="plan")
    assert from_text.plan is not None
    assert from_path.plan is not None
    for key in ("prefix", "cycle", "cost"):
        assert from_text.plan[key] == from_path.plan[key]
    assert "trace.json" not in from_text.artifacts


def test_errors_are_typed_and_carry_diagnostics(tmp_path: Path) -> None:
    mission = _mission()
    mission["task"] = ["visit nowhere"]
    with pytest.raises(tlmpc.InvalidInputError) as caught:
        tlmpc.compile(mission)
    assert caught.value.exit_code == 1
    assert any("nowhere" in d.message for d in caught.value.diagnostics)
    with pytest.raises(tlmpc.UsageError):
        tlmpc.compile(tmp_path / "missing.yaml")
    with pytest.raises(tlmpc.UsageError):
        tlmpc.read_output(tmp_path)
    with pytest.raises(tlmpc.UsageError):
        tlmpc.compile(_mission(), until="no-such-stage")


def test_a_trace_or_a_path_python_cannot_take_is_a_diagnostic(tmp_path: Path) -> None:
    compiled = tlmpc.compile(_mission())
    trace = compiled.artifacts["trace.json"]
    for changed, code in (
        ({"workspace": "x"}, "V004"),
        ({"workspace": [[1]]}, "V004"),
        ({"points": [[0, 10**400, 1], [2, 1, 1]]}, "V024"),  # too large for a float
        ({"regions": {"a": [[0, 0], [10**400, 0], [0, 1]]}}, "V004"),
    ):
        with pytest.raises(tlmpc.UsageError) as caught:
            tlmpc.verify_trace({**trace, **changed})
        assert caught.value.diagnostics[0].code == code, changed
    for call in (
        lambda: compiled.write(tmp_path / "a\x00b"),
        lambda: tlmpc.read_output("a\x00b"),
    ):
        with pytest.raises(tlmpc.UsageError) as refused:
            call()
        assert refused.value.diagnostics[0].code == "U075"


def test_impossible_mission_raises_no_plan() -> None:
    mission = _mission()
    mission["task"] = ["visit dock", "avoid dock"]
    with pytest.raises(tlmpc.TlmpcError) as caught:
        tlmpc.compile(mission)
    assert caught.value.exit_code == 1


def test_check_reports_problems_without_raising() -> None:
    assert tlmpc.check(_mission()) == []
    problems = tlmpc.check("version: 1\nname: x\n")
    assert problems
    assert problems[0].severity == "error"


def test_translate() -> None:
    automaton = tlmpc.translate("G F a & G F b")
    assert automaton.num_states == 1
    assert automaton.num_acc == 2


def test_jupyter_representations() -> None:
    result = tlmpc.compile(_mission())
    page = result._repr_html_()
    assert "F(dock &amp; F home)" in page
    assert "<svg" in page
    assert tlmpc.compile(_mission(), until="plan")._repr_svg_() is None


def test_import_tlmpc_is_light() -> None:
    code = (
        "import sys, tlmpc\n"
        "heavy = {'numpy', 'scipy', 'matplotlib', 'shapely', 'jsonschema', 'lark', 'yaml'}\n"
        "print(sorted(heavy & set(sys.modules)))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    )
    assert done.stdout.strip() == "[]"


def test_read_output_rejects_an_artifact_that_fails_its_schema(tmp_path: Path) -> None:
    out = tlmpc.compile(_mission(), until="plan").write(tmp_path / "out")
    witness = json.loads((out / "witness.json").read_text())
    del witness["cycle"]
    (out / "witness.json").write_text(json.dumps(witness))
    with pytest.raises(tlmpc.UsageError) as caught:
        tlmpc.read_output(out)
    assert caught.value.diagnostics[0].code == "U071"
    assert caught.value.diagnostics[0].file == str(out / "witness.json")


def test_the_repr_of_a_compiled_mission_is_one_short_line() -> None:
    compiled = tlmpc.compile(ROOT / "specs" / "example1.yaml")
    text = repr(compiled)
    summary = compiled.summary
    triangles = next(s for s in summary["stages"] if s["name"] == "abstraction")["sizes"]
    assert "\n" not in text
    assert len(text) < 200  # not every artifact
    assert text.startswith("Compiled(source=")
    assert f"triangles={triangles['triangles']}" in text
    assert f"satisfied={summary['verdict']['satisfied']}" in text
    assert f"artifacts={len(compiled.artifacts)}" in text


def test_reactive_outputs_have_their_own_executor(tmp_path: Path) -> None:
    from tlmpc.runtime.reactive import ReactiveExecutor

    root = Path(__file__).resolve().parents[2]
    compiled = tlmpc.compile(root / "specs" / "reactive" / "guard.yaml")
    with pytest.raises(tlmpc.UsageError) as refused:
        tlmpc.executor(compiled)
    assert refused.value.diagnostics[0].code == "R025"
    executor = tlmpc.reactive_executor(compiled)
    assert isinstance(executor, ReactiveExecutor)
    vx, vy = executor.command((1.0, 1.0), 0.0, {"person": True, "alarm": False})
    assert math.isfinite(vx)
    assert math.isfinite(vy)
    assert executor.actions == {"camera": True}  # "if you sense person then do camera"
    static = tlmpc.compile(root / "specs" / "example1.yaml")
    with pytest.raises(tlmpc.UsageError):
        tlmpc.reactive_executor(static)
