"""No-plan explanations: the real reason, the blamed part quoted and located in the file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import Diagnostic, NoPlanError, UsageError, error
from tlmpc.pipeline.stages import compile_mission
from tlmpc.planning import budget as budget_module
from tlmpc.planning import complete as complete_module

MAP = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 12, 8]}
  holes: [HOLES]
regions:
  a: {rect: [1, 1, 3, 3]}
  b: {rect: [9, 5, 11, 7]}
  c: {rect: [4, 0, 5, 8]}
  goal: {rect: [9, 1, 11, 3]}
  moat: {rect: [4, 5, 5, 6]}
robot: {start: [0.5, 7.5]}
"""
#: A wall of holes from the bottom to the top at x = 7: b and goal are cut off.
WALL = "{rect: [7, 0, 7.5, 8]}"
#: Holes around goal leaving one door at its left, where `moat` is.
RING = (
    "{rect: [8, 0.5, 11.5, 1]}, {rect: [8, 3, 11.5, 3.5]}, {rect: [11, 1, 11.5, 3]}, "
    "{rect: [8, 1, 8.5, 1.8]}, {rect: [8, 2.2, 8.5, 3]}"
)


def _no_plan(tmp_path: Path, holes: str, task: str) -> tuple[Diagnostic, list[str]]:
    text = MAP.replace("HOLES", holes) + task
    path = tmp_path / "m.yaml"
    path.write_text(text)
    with pytest.raises(NoPlanError) as raised:
        compile_mission(path, until="plan")
    first = raised.value.diagnostics[0]
    assert first.file == str(path), "points at the mission file"
    return first, text.splitlines()


def _col(lines: list[str], line: int, needle: str) -> int:
    return lines[line - 1].index(needle) + 1


def test_forbidden_region_is_never_blamed_for_a_patrol(tmp_path: Path) -> None:
    first, lines = _no_plan(tmp_path, WALL, 'ltl: "G !c & G F a & G F b"\n')
    assert first.code == "P010"
    assert "`G F b`" in first.message
    assert "'c'" not in first.message + (first.hint or "")
    assert "region 'b' cannot be reached" in (first.hint or "")
    assert first.line == len(lines)
    assert first.col == _col(lines, len(lines), "G F b")


def test_moat_is_not_blamed_when_the_goal_is_cut_off(tmp_path: Path) -> None:
    first, lines = _no_plan(tmp_path, WALL, 'ltl: "F goal & G(!moat | goal)"\n')
    assert "`F goal`" in first.message
    assert "moat" not in first.message + (first.hint or "")
    assert (first.line, first.col) == (len(lines), _col(lines, len(lines), "F goal"))


def test_goal_behind_a_forbidden_moat_blames_both_parts_with_parentheses(
    tmp_path: Path,
) -> None:
    # Holes ring goal; its only door is a region the second part forbids outside goal.
    holes = RING
    task = 'ltl: "F goal & G(!door | goal)"\n'
    text_map = MAP.replace("  moat: {rect: [4, 5, 5, 6]}\n", "  door: {rect: [8, 1.8, 8.5, 2.2]}\n")
    path = tmp_path / "m.yaml"
    path.write_text(text_map.replace("HOLES", holes) + task)
    with pytest.raises(NoPlanError) as raised:
        compile_mission(path, until="plan")
    first = raised.value.diagnostics[0]
    assert first.code == "P011"
    assert "`F goal`" in first.message
    assert "`G(!door | goal)`" in first.message, "quoted with its parentheses"
    assert "region 'goal' can only be reached through regions the task forbids" in (
        first.hint or ""
    )


def test_task_phrases_are_located_at_their_phrase(tmp_path: Path) -> None:
    task = "task:\n  - visit a\n  - avoid c\n  - " + json.dumps("patrol a, b") + "\n"
    first, lines = _no_plan(tmp_path, "", task)
    assert first.code == "P011"
    assert "`avoid c`" in first.message
    assert "`patrol a, b`" in first.message
    assert "`visit a`" not in first.message, "only the parts that fail together"
    assert "region 'c'" not in first.message + (first.hint or ""), "c is only forbidden"
    assert "region 'b' can only be reached through regions the task forbids" in (first.hint or "")
    assert (first.line, first.col) == (len(lines) - 1, _col(lines, len(lines) - 1, "avoid c"))


@pytest.mark.parametrize("task", ["visit corner", "visit a then corner"])
def test_a_region_the_body_cannot_enter_is_named_not_an_overlap(tmp_path: Path, task: str) -> None:
    # a corner region 0.1 wide, within a 0.3 body's radius of both walls: no triangle of the
    # planner's space holds it, so the automaton over the map's letters has no edge
    text = (
        "version: 1\nworkspace:\n  boundary: {rect: [0, 0, 10, 10]}\nregions:\n"
        "  a: {rect: [1, 1, 3, 3]}\n  corner: {rect: [9.9, 9.9, 10, 10]}\n"
        f"robot: {{start: [5, 5], radius: 0.3}}\ntask: [{task}]\n"
    )
    path = tmp_path / "m.yaml"
    path.write_text(text)
    with pytest.raises(NoPlanError) as raised:
        compile_mission(path, until="plan")
    first = raised.value.diagnostics[0]
    assert first.code == "P010"
    assert "region 'corner' has no free space the robot can be in" in (first.hint or "")
    assert "overlap" not in first.message + (first.hint or "")


def test_a_part_kept_because_the_rest_was_beyond_the_budget_is_not_called_needed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    task = "task:\n  - visit a\n  - avoid c\n  - " + json.dumps("patrol a, b") + "\n"
    first, _lines = _no_plan(tmp_path, "", task)
    assert (first.hint or "").startswith("each is possible without the others")

    real_check = budget_module.check_product_size

    def beyond_without_c(abstraction: Abstraction, automaton: Automaton) -> object:
        # the patrol alone (no `c` in its automaton) is left beyond the budget
        if "c" not in automaton.aps:
            raise UsageError(error("P040", "beyond the budget (test)"))
        return real_check(abstraction, automaton)

    monkeypatch.setattr(complete_module, "check_product_size", beyond_without_c)
    first, _lines = _no_plan(tmp_path, "", task)
    assert first.code == "P011"
    assert "`avoid c`" in first.message, "kept: the rest without it is undecided"
    hint = first.hint or ""
    assert "each is possible without the others" not in hint
    assert "`avoid c`, without which the rest is beyond the planner's budget" in hint
