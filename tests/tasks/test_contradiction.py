"""Contradictory tasks: emptiness agrees with Spot; `tlmpc check` locates the core."""

from __future__ import annotations

import io
import subprocess
import sys
from pathlib import Path

import pytest
from ci_oracles import import_oracle
from hypothesis import given
from hypothesis import strategies as st
from strategies import formulas

from tlmpc.cli import main
from tlmpc.ltl import parse_ltl, to_text
from tlmpc.ltl.ast import Formula
from tlmpc.tasks.contradiction import (
    MAX_TEMPORAL_OPERATORS,
    TaskPart,
    contradictory,
    find_contradiction,
    is_satisfiable,
)

spot = import_oracle("spot")

MISSION = """\
version: 1
workspace:
  boundary: {{rect: [0, 0, 10, 10]}}
regions:
  x: {{rect: [1, 1, 2, 2]}}
  y: {{rect: [5, 5, 6, 6]}}
  z: {{rect: [7, 1, 8, 2]}}
robot: {{start: [0.5, 0.5]}}
{task}
"""


@given(formulas())
def test_emptiness_agrees_with_spot(formula: Formula) -> None:
    expected = not spot.formula(to_text(formula)).translate().is_empty()
    assert is_satisfiable(formula) == expected, to_text(formula)


@pytest.mark.parametrize(
    ("text", "satisfiable"),
    [
        ("F x & G !x", False),
        ("G F x & F G !x", False),
        ("(!x U y) & G !y", False),
        ("F x & G !y", True),
        ("G(x -> F y) & G F x & G !y", False),
        ("G(x -> F y) & G F x", True),
        ("F G x & G F !x", False),
    ],
)
def test_known_contradictions(text: str, satisfiable: bool) -> None:
    assert is_satisfiable(parse_ltl(text)) is satisfiable
    assert (not spot.formula(text).translate().is_empty()) is satisfiable


def test_the_core_leaves_out_innocent_phrases() -> None:
    parts = [
        TaskPart(formula=parse_ltl("F z"), text="visit z", kind="phrase", line=3, col=5),
        TaskPart(formula=parse_ltl("F x"), text="visit x", kind="phrase", line=4, col=5),
        TaskPart(formula=parse_ltl("F y"), text="visit y", kind="phrase", line=5, col=5),
        TaskPart(formula=parse_ltl("G !x"), text="avoid x", kind="phrase", line=6, col=5),
    ]
    found = find_contradiction(parts, file="m.yaml")
    assert found is not None
    assert (found.code, found.line, found.col) == ("T011", 4, 5)
    assert "'avoid x' (line 6)" in found.message
    assert "visit z" not in found.message
    assert "visit y" not in found.message
    assert find_contradiction(parts[:3], file="m.yaml") is None


def test_groups_are_expanded_before_the_check() -> None:
    parts = [
        TaskPart(formula=parse_ltl("F rooms"), text="visit rooms", kind="phrase", line=1),
        TaskPart(formula=parse_ltl("G !x"), text="avoid x", kind="phrase", line=2),
    ]
    assert find_contradiction(parts, groups={"rooms": ["x", "y"]}) is None
    assert find_contradiction(parts, groups={"rooms": ["x"]}) is not None


def _check(tmp_path: Path, task: str) -> tuple[int, str]:
    path = tmp_path / "mission.yaml"
    path.write_text(MISSION.format(task=task))
    err = io.StringIO()
    code = main(["check", str(path)], out=io.StringIO(), err=err)
    return code, err.getvalue()


def test_check_reports_a_contradiction_at_the_phrase(tmp_path: Path) -> None:
    code, err = _check(tmp_path, "task:\n  - visit y\n  - visit x then z\n  - avoid x")
    assert code == 1
    assert f"{tmp_path / 'mission.yaml'}:11:5: error[T011]" in err
    assert "'avoid x' (line 12)" in err


def test_check_reports_an_unsatisfiable_ltl_at_the_formula(tmp_path: Path) -> None:
    code, err = _check(tmp_path, "ltl: 'F G x & G F !x'")
    assert code == 1
    assert ":9:7: error[L020]" in err


def test_a_satisfiable_task_passes(tmp_path: Path) -> None:
    code, _ = _check(tmp_path, "task:\n  - visit x then y while avoiding z\n")
    assert code == 0


def test_the_check_stays_light(tmp_path: Path) -> None:
    path = tmp_path / "mission.yaml"
    path.write_text(MISSION.format(task="task:\n  - visit x\n  - avoid x"))
    script = (
        "import sys, io\n"
        "from tlmpc.cli import main\n"
        f"code = main(['check', {str(path)!r}], out=io.StringIO(), err=io.StringIO())\n"
        "heavy = sorted(m for m in sys.modules if m.split('.')[0] in "
        "('scipy', 'cvxpy', 'triangle', 'matplotlib', 'clarabel'))\n"
        "print(code, heavy)\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == "1 []"


@given(st.lists(formulas(max_leaves=6), min_size=1, max_size=4))
def test_a_reported_contradiction_is_one(parts: list[Formula]) -> None:
    """Sound: never reports a satisfiable task; complete on groups small enough to check."""
    whole = spot.formula(" & ".join(f"({to_text(p)})" for p in parts))
    empty = whole.translate().is_empty()
    if contradictory(parts):
        assert empty
    elif sum(sum(1 for _ in p.walk()) for p in parts) <= MAX_TEMPORAL_OPERATORS:
        assert not empty


def test_independent_groups_are_checked_alone(monkeypatch: pytest.MonkeyPatch) -> None:
    many = parse_ltl(" & ".join(f"F r{i}" for i in range(60)) + " & G !r3")
    assert contradictory([many])  # found in the group {F r3, G !r3}, not in 2^60 states
    tangled = parse_ltl(" & ".join(f"G(r{i} -> F r{i + 1})" for i in range(20)))

    def refuse(formula: Formula) -> bool:
        raise AssertionError(f"translated a group too large to check: {to_text(formula)}")

    monkeypatch.setattr("tlmpc.tasks.contradiction.is_satisfiable", refuse)
    assert not contradictory([tangled])  # too large: not checked, not reported
