"""Where a task's automaton beyond the translation's budget (P041) is placed: the translation
knows only the formula, so `check` and `compile` place its refusal in the mission file, at the
entry whose automaton alone is too large, or at `task:` when only their conjunction is."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from tlmpc.automata.translate import translate
from tlmpc.base.errors import UsageError, error
from tlmpc.cli import main
from tlmpc.mission.load import load_mission, place_translation_refusal

PAIRS = 17

# F((p0 | q0) & ... & (p16 | q16)): one state with 2^17 terms, beyond the 100,000 a state
# may have; unsatisfiable on the map (the regions are disjoint), so `compile` translates it
# again without the map's letters to explain why there is no plan.
TOO_LARGE = "F (" + " & ".join(f"(p{i} | q{i})" for i in range(PAIRS)) + ")"


def _mission(folder: Path, tail: str) -> Path:
    regions = "".join(
        f"  p{i}: {{rect: [{2 * i}, 0, {2 * i + 1}, 1]}}\n"
        f"  q{i}: {{rect: [{2 * i}, 1.5, {2 * i + 1}, 2.5]}}\n"
        for i in range(PAIRS)
    )
    mission = folder / "budget.yaml"
    mission.write_text(
        "version: 1\n"
        "name: budget\n"
        "workspace: {boundary: {rect: [-1, -1, 40, 4]}}\n"
        f"regions:\n{regions}"
        "robot: {start: [0.5, 3]}\n" + tail
    )
    return mission


def _place(text: str, line_start: str, at: str) -> tuple[int, int]:
    """(line, col) of ``at`` on the line starting with ``line_start``, counted by hand."""
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith(line_start):
            return number, line.index(at) + 1
    raise AssertionError(line_start)


@pytest.mark.parametrize("command", ["check", "compile"])
def test_the_entry_too_large_alone_is_blamed(tmp_path: Path, command: str) -> None:
    mission = _mission(tmp_path, f'task: [visit p0]\nltl: "{TOO_LARGE}"\n')
    line, col = _place(mission.read_text(), "ltl:", "F (")
    args = (
        ["check", str(mission)]
        if command == "check"
        else ["compile", str(mission), "-o", str(tmp_path / "out")]
    )
    out, err = io.StringIO(), io.StringIO()
    code = main(args, out=out, err=err)
    # check: the file is invalid (1); compile: the translation's refusal (2)
    assert code == (1 if command == "check" else 2)
    assert f"{mission}:{line}:{col}: error[P041]" in out.getvalue() + err.getvalue()


def test_a_conjunction_of_small_entries_is_placed_at_the_task_key(tmp_path: Path) -> None:
    # two phrases of 9 and 8 recurrences: each alone has a few hundred edges, together one
    # state has 2^17 ways to proceed
    first = ", ".join(f"p{i}" for i in range(9))
    second = ", ".join(f"p{i}" for i in range(9, PAIRS))
    mission = _mission(tmp_path, f"task:\n  - patrol {first}\n  - patrol {second}\n")
    loaded = load_mission(mission)
    with pytest.raises(UsageError) as refused:
        translate(loaded.formula)
    [refusal] = refused.value.diagnostics
    placed = place_translation_refusal(refusal, loaded)
    assert (placed.file, placed.line, placed.col) == (
        str(mission),
        *_place(mission.read_text(), "task:", "task"),
    )
    assert placed.path == "$.task"
    assert placed.code == "P041"
    assert placed.hint is not None
    assert "conjunction of the task's 2 entries" in placed.hint


def test_one_phrase_too_large_among_small_ones_is_blamed(tmp_path: Path) -> None:
    everything = ", ".join(f"p{i}" for i in range(PAIRS))
    mission = _mission(tmp_path, f"task:\n  - visit q0\n  - patrol {everything}\n")
    loaded = load_mission(mission)
    with pytest.raises(UsageError) as refused:
        translate(loaded.formula)
    placed = place_translation_refusal(refused.value.diagnostics[0], loaded)
    assert (placed.line, placed.col) == _place(mission.read_text(), "  - patrol", "patrol")
    assert placed.path == "$.task[1]"


def test_a_mission_file_gone_since_it_was_loaded_leaves_the_refusal_as_it_is(
    tmp_path: Path,
) -> None:
    mission = _mission(tmp_path, "task: [visit p0, visit q0]\n")
    loaded = load_mission(mission)
    mission.unlink()
    refusal = error("P041", "the automaton is beyond the translation's budget", hint="split")
    assert place_translation_refusal(refusal, loaded) == refusal
