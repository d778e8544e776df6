"""A mission beyond the convex cells' budget is refused saying that no cell plan was tried."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import tlmpc
import tlmpc.abstraction.lines
import tlmpc.planning.cells

EXAMPLE1 = Path(__file__).parents[2] / "specs" / "example1.yaml"


def _example1(tmp_path: Path, disturbance: float) -> Path:
    text = EXAMPLE1.read_text(encoding="utf-8")
    disturbed = text.replace("max_speed: 1.0}", f"max_speed: 1.0, disturbance: {disturbance}}}")
    assert disturbed != text
    source = tmp_path / "example1.yaml"
    source.write_text(disturbed, encoding="utf-8")
    return source


def _refusal(source: Path) -> tlmpc.TlmpcError:
    with pytest.raises(tlmpc.TlmpcError) as caught:
        tlmpc.compile(source, until="control")
    return caught.value


def test_beyond_the_budget_the_hint_says_no_cell_plan_was_tried(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(tlmpc.planning.cells, "MAX_TRIANGLES", 10)
    monkeypatch.setattr(tlmpc.abstraction.lines, "MAX_SIDES", 3)
    monkeypatch.setattr(tlmpc.abstraction.lines, "MAX_REFLEX_WORK", 5)
    refused = _refusal(_example1(tmp_path, 0.5))  # compiles on cells within the budget
    hints = {d.hint for d in refused.diagnostics if d.code == "C032"}
    assert len(hints) == 1
    (hint,) = hints
    assert hint is not None
    assert "no plan on convex cells (the plan stage's last rung) was tried" in hint
    assert "at most 10 triangles" in hint
    assert "at most 3 straight sides" in hint
    assert "at most 5 work units" in hint
    assert "(its mesh has " in hint  # the size that exceeds the triangles' budget


def test_within_the_budget_the_hint_states_the_cells_bound(tmp_path: Path) -> None:
    refused = _refusal(_example1(tmp_path, 0.7))  # beyond what Example 1's cells reject
    (hint,) = {d.hint for d in refused.diagnostics if d.code == "C032"}
    assert hint is not None
    assert "on convex cells" in hint
    assert "plans reject at most" in hint
    assert "was tried" not in hint


@pytest.mark.parametrize("options", ["", "options: {goal_depth: 0}\n"])
def test_without_the_cells_own_mesh_the_hint_states_the_mission_mesh_cells_bound(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, options: str
) -> None:
    """The bound on the cells of the meshes tried is computed for the refusal alone (a plan
    the cells' rung carries never needs it): with the cells' own meshes over their budgets,
    Example 1 at 0.5 (with goal cores, the ladder's meshes; without, the one mesh) is
    refused stating what its meshes' cells reject, a rectangle's corners left by part of a
    side: cos 67.5 degrees."""
    monkeypatch.setattr(tlmpc.abstraction.lines, "MAX_SIDES", 3)
    monkeypatch.setattr(tlmpc.abstraction.lines, "MAX_REFLEX_WORK", 5)
    source = _example1(tmp_path, 0.5)
    source.write_text(source.read_text(encoding="utf-8") + options, encoding="utf-8")
    refused = _refusal(source)
    (hint,) = {d.hint for d in refused.diagnostics if d.code == "C032"}
    assert hint is not None
    assert f"plans reject at most {math.cos(math.radians(67.5)):.6g}" in hint
    assert "was tried" not in hint
