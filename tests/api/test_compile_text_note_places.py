"""`tlmpc.compile(text)` places the workspace's notes (G020 merged holes, G021 narrow
passages) on the lines of the YAML text, as `tlmpc.compile(path)` does."""

from __future__ import annotations

from pathlib import Path

import tlmpc
from tlmpc.api import Compiled

# the two holes of line 5 overlap: G020 there
MISSION = """\
version: 1
name: case
workspace:
  boundary: {rect: [0, 0, 10, 10]}
  holes: [{rect: [4, 4, 6, 6]}, {rect: [5, 5, 7, 7]}]
regions:
  a: {rect: [1, 1, 2, 2]}
robot: {start: [1.5, 8]}
task: [visit a]
"""


def _notes(result: Compiled) -> list[tuple[str, int | None]]:
    return [(d.code, d.line) for d in result.warnings if d.code in ("G020", "G021")]


def test_the_notes_of_a_text_are_on_its_lines(tmp_path: Path) -> None:
    from_text = _notes(tlmpc.compile(MISSION, until="load"))
    assert from_text == [("G020", 5)]
    path = tmp_path / "case.yaml"
    path.write_text(MISSION)
    assert _notes(tlmpc.compile(str(path), until="load")) == from_text
