"""Exact no-plan reasons (P001, P002, P003) blame the parts behind that reason, and only them.

A task can fail for an exact reason (the start breaks an invariant, the task fails at the
first instant, the task contradicts itself) while a different subset of its parts fails for
another reason (a goal walled off, two regions that would have to overlap). The blamed parts
must be those behind the reason given. Spot is the oracle for the quoted formulas: they must
fail as the diagnostic says, and every top-level conjunct of them must be needed for it.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tlmpc.base.errors import Diagnostic, NoPlanError
from tlmpc.pipeline.stages import compile_mission

spot = pytest.importorskip("spot")

MAP = """\
version: 1
workspace:
  boundary: [[0, 0], [10, 0], [10, 10], [0, 10]]
  holes: [{rect: [6, 6, 9.5, 6.5]}, {rect: [6, 9, 9.5, 9.5]}, {rect: [6, 6.5, 6.5, 9]},
          {rect: [9, 6.5, 9.5, 9]}]
regions:
  a: {rect: [1, 1, 3, 3]}
  b: {rect: [1, 7, 3, 9]}
  c: {rect: [4, 4, 5, 5]}
  walled: {rect: [7, 7, 8, 8]}
robot: {start: START}
task:
"""


def _no_plan(tmp_path: Path, start: str, task: list[str], ltl: str = "") -> tuple[Diagnostic, str]:
    text = MAP.replace("START", start) + "".join(f"  - {phrase}\n" for phrase in task) + ltl
    path = tmp_path / "m.yaml"
    path.write_text(text)
    with pytest.raises(NoPlanError) as raised:
        compile_mission(path, until="plan")
    return raised.value.diagnostics[0], text


def _line_of(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if needle in line)


def _quoted(text: str) -> str:
    return text.split("`")[1]


def _conjuncts(formula: str) -> list[str]:
    parsed = spot.formula(formula)
    parts = list(parsed) if parsed.kind() == spot.op_And else [parsed]
    return [str(p) for p in parts]


def _satisfiable(formula: str) -> bool:
    return not spot.translate(formula).is_empty()


def _each_needed(conjuncts: list[str], extra: str = "1") -> bool:
    """Dropping any one conjunct makes the rest (with ``extra``) satisfiable."""
    return all(
        _satisfiable(" & ".join([f"({c})" for c in conjuncts[:i] + conjuncts[i + 1 :]] + [extra]))
        for i in range(len(conjuncts))
    )


@pytest.mark.parametrize("order", ["avoid-first", "visit-first"])
def test_a_start_in_a_forbidden_region_blames_the_avoid_not_a_walled_off_goal(
    tmp_path: Path, order: str
) -> None:
    task = ["avoid a", "visit walled"]
    if order == "visit-first":
        task.reverse()
    first, text = _no_plan(tmp_path, "[2, 2]", task)
    assert first.code == "P002"
    assert "`G !a`" in first.message
    assert first.line == _line_of(text, "- avoid a")


def test_a_task_failing_at_the_start_quotes_only_the_part_that_fails_there(
    tmp_path: Path,
) -> None:
    first, text = _no_plan(tmp_path, "[2, 8]", ["visit a", "patrol a and c", "avoid b until c"])
    assert first.code == "P003"
    assert first.line == _line_of(text, "- avoid b until c")
    quoted = _quoted(first.hint or "")
    at_start = "b & !a & !c & !walled"
    assert not _satisfiable(f"({quoted}) & {at_start}"), "the quoted part fails at the start"
    assert _each_needed(_conjuncts(quoted), at_start), f"`{quoted}` quotes parts not needed"


def test_a_contradiction_names_both_of_its_parts_and_no_other(tmp_path: Path) -> None:
    # `F(c & b)` alone fails on this map (c and b do not overlap), but the reason given is the
    # contradiction with `avoid b`, so both are named and `visit walled` is not.
    first, text = _no_plan(tmp_path, "[5, 2]", ["avoid b", "visit walled"], 'ltl: "F(c & b)"\n')
    assert first.code == "P001"
    quoted = _quoted(first.message)
    assert not _satisfiable(quoted)
    assert _each_needed(_conjuncts(quoted)), f"`{quoted}` quotes parts not needed"
    assert first.line == _line_of(text, "- avoid b")
    assert "`avoid b`" in (first.hint or "")
    assert "`F(c & b)`" in (first.hint or "")
    assert "walled" not in first.message + (first.hint or "")
