"""docs/planning.md's completeness table quotes today's meshes: every shipped spec's final
triangle count with its U-turn splits, and the dead end (``bench/bench_completeness.py``'s
mission) on the default mesh and on the coarse one, where it needs a U-turn."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tlmpc.pipeline.stages import ABSTRACTION, compile_mission

ROOT = Path(__file__).resolve().parents[2]
HEADER = "| mission | triangles (U-turn splits) | CPU s |"
DEAD_END = """\
version: 1
name: dead-end
workspace:
  boundary: [[0, 0], [10, 0], [10, 4], [6, 4], [6, 10], [5, 10], [5, 4], [0, 4]]
regions:
  tip: {rect: [5, 9, 6, 10]}
  base: {rect: [0, 0, 2, 2]}
robot: {start: [9, 1], max_speed: 1.0}
task: [visit tip then base]
"""


def _rows() -> dict[str, str]:
    text = (ROOT / "docs" / "planning.md").read_text(encoding="utf-8")
    table = text[text.index(HEADER) :].split("\n\n", 1)[0].splitlines()[2:]
    cells = [[cell.strip() for cell in line.strip("|").split("|")] for line in table]
    return {mission: triangles for mission, triangles, _cpu in cells}


def _mission(name: str, tmp_path: Path) -> Path:
    if name.startswith("dead end"):
        coarse = "coarse mesh" in name
        options = "options: {min_angle: null, goal_depth: 0}\n" if coarse else ""
        path = tmp_path / "dead-end.yaml"
        path.write_text(DEAD_END.replace("task:", options + "task:"), encoding="utf-8")
        return path
    return ROOT / "specs" / f"{name}.yaml"


@pytest.mark.parametrize("name", sorted(_rows()))
def test_the_table_quotes_the_final_mesh(name: str, tmp_path: Path) -> None:
    quoted = _rows()[name]
    result = compile_mission(_mission(re.sub(r"^the same ", "", name), tmp_path), until="verify")
    abstraction = result.compilation.get(ABSTRACTION)
    splits = abstraction.stats.get("split_for_u_turns", 0)
    assert quoted == f"{abstraction.num_triangles:,} ({splits})"
