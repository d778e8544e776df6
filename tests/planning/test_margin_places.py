"""The margin's warnings (R006, R007, R008) are placed at `options.margin` (they had the file
name alone), as every problem a later stage finds in a value of the mission."""

from __future__ import annotations

import io
import json
from pathlib import Path

from tlmpc.cli import main

MISSION = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 10]}
  holes:
    - {rect: [4, 0, 6, 4.8]}
    - {rect: [4, 5.2, 6, 10]}
regions:
  a: {rect: [0.5, 0.5, 2, 2]}
  b: {rect: [8, 8, 9.5, 9.5]}
robot: {start: [1, 1], max_speed: 1.0, radius: 0.1}
task: [visit a then b]
options:
  margin: 0.3
"""


def test_margin_warnings_point_at_the_margin(tmp_path: Path) -> None:
    path = tmp_path / "door.yaml"
    path.write_text(MISSION)
    out = io.StringIO()
    code = main(["compile", str(path), "-o", str(tmp_path / "out"), "--json"], out, io.StringIO())
    assert code == 0
    # the oracle: where `margin: 0.3` is written, found in the text itself
    lines = MISSION.splitlines()
    line = next(k for k, text in enumerate(lines, 1) if text.strip().startswith("margin:"))
    col = lines[line - 1].index("0.3") + 1
    diagnostics = json.loads(out.getvalue())["diagnostics"]
    margins = [d for d in diagnostics if d["code"] in ("R006", "R007", "R008")]
    # the door is 0.4 wide: the body (0.2 across) passes, the margin (0.3 each side) cannot
    assert {d["code"] for d in margins} >= {"R006", "R008"}
    for d in margins:
        assert (d.get("line"), d.get("col")) == (line, col), d
