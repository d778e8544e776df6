"""Inputs nested as deep as tlmpc accepts them go through every command; deeper ones are
refused at their own file, and a batch goes on with the next file.

The reader's limit (L005, :data:`tlmpc.base.depth.NESTING_LIMIT` levels) is what the passes
after it must handle: a formula 340 levels deep, which the reader accepts, once exhausted the
stack in the printer, and a long sequence of task steps (two levels each) with it.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hostile_harness import run_hostile, work_fixture  # noqa: F401 (fixture, by its name)

from tlmpc.base.depth import NESTING_LIMIT

MISSION = """version: 1
workspace:
  boundary: {{rect: [0, 0, 10, 10]}}
regions:
  a: {{rect: [1, 1, 2, 2]}}
  b: {{rect: [8, 8, 9, 9]}}
robot: {{start: [5, 5]}}
{task}
"""


def _steps(count: int) -> str:
    """A task phrase of ``count`` steps: two levels of the formula each."""
    return "task: [visit " + " then ".join("ab"[k % 2] for k in range(count)) + "]"


def _nested(levels: int) -> str:
    """An LTL formula nested ``levels`` deep."""
    return "ltl: '" + "F (a & " * (levels // 2) + "b" + ")" * (levels // 2) + "'"


def test_the_deepest_accepted_inputs_are_checked(work: Path) -> None:
    deepest = NESTING_LIMIT // 2 - 2  # steps whose formula stays within the limit
    (work / "steps.yaml").write_text(MISSION.format(task=_steps(deepest)))
    (work / "ltl.yaml").write_text(MISSION.format(task=_nested(NESTING_LIMIT - 2)))
    result = run_hostile(work, "check", "--explain", "steps.yaml", "ltl.yaml")
    assert result.code == 0, result.err
    assert "2 of 2 mission file(s) valid" in result.err


def test_a_file_nested_too_deep_is_refused_at_itself_and_the_batch_goes_on(work: Path) -> None:
    (work / "good.yaml").write_text(MISSION.format(task="task: [visit a then b]"))
    (work / "deep.yaml").write_text(MISSION.format(task=_steps(20 * NESTING_LIMIT)))
    (work / "bad.yaml").write_text("version: 1\nworkspace: {boundary: [\n")
    result = run_hostile(work, "check", "good.yaml", "deep.yaml", "bad.yaml")
    assert result.code == 2
    assert result.err.count("error[") == 2, result.err
    assert "bad.yaml:" in result.err
    assert result.err.startswith("deep.yaml: error[U036]"), result.err
    assert "1 of 3 mission file(s) valid, 1 invalid, 1 unreadable" in result.err


def test_a_spec_as_deep_as_a_formula_may_be_is_solved(work: Path) -> None:
    depth = NESTING_LIMIT - 10
    body = "(" * depth + "y'" + ")" * depth
    (work / "deep.spc").write_text(f"ENV: x;\nSYS: y;\nSYSTRANS: [] {body};\nSYSGOAL: []<> y;\n")
    result = run_hostile(work, "synth", "deep.spc")
    assert result.code == 0, result.err
    assert result.out.startswith("realizable")


def test_a_spec_nested_beyond_it_is_refused_at_its_file(work: Path) -> None:
    depth = 50 * NESTING_LIMIT
    body = "(" * depth + "y'" + ")" * depth
    (work / "deeper.spc").write_text(f"ENV: x;\nSYS: y;\nSYSTRANS: [] {body};\n")
    result = run_hostile(work, "synth", "deeper.spc", located=False)
    assert result.code == 2
    assert result.err.startswith("deeper.spc:"), result.err


def test_a_file_refused_for_its_depth_is_never_reported_valid(
    work: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # loaded whole, then too deep for the last step (printing its formula): the JSON entry
    # must not keep the 'ok' it had before
    import tlmpc.ltl.printer

    def too_deep(formula: object) -> str:
        raise RecursionError

    monkeypatch.setattr(tlmpc.ltl.printer, "to_text", too_deep)
    (work / "steps.yaml").write_text(MISSION.format(task=_steps(3)))
    result = run_hostile(work, "check", "--json", "steps.yaml", located=False)
    assert result.code == 2
    (entry,) = json.loads(result.out)["result"]["files"]
    assert entry["ok"] is False
    assert [d["code"] for d in entry["diagnostics"]] == ["U036"]
