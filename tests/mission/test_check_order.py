"""`tlmpc check` reports a file's problems best first: errors, then by their place in the file,
the geometry found after the task (thin features, G030) included, as `compile` does."""

from __future__ import annotations

import io
import json
from pathlib import Path

from tlmpc.cli import main

# A hole (line 4) and a region (line 7) each a billionth of the map wide: thinner than the
# snapping grid, so both are G030; written off the grid, so check looks at them.
THIN = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 10]}
  holes: [{rect: [3.253496167837482, 6, 3.253496168837482, 7]}]
regions:
  a: {rect: [2.453496167837482, 1.0, 2.953496167837482, 3.0]}
  b: {rect: [3.253496167837482, 1.5, 3.253496168837482, 2.5]}
robot: {start: [9, 9]}
task: [visit a, visit b]
"""


def _places(argv: list[str]) -> list[tuple[str, int, int]]:
    out = io.StringIO()
    main([*argv, "--json"], out=out, err=io.StringIO())
    return [
        (d["code"], d["line"], d["col"])
        for d in json.loads(out.getvalue())["diagnostics"]
        if d["severity"] == "error"
    ]


def test_thin_features_are_reported_in_file_order(tmp_path: Path) -> None:
    path = tmp_path / "thin.yaml"
    path.write_text(THIN)
    checked = _places(["check", str(path)])
    assert checked == [("G030", 4, 11), ("G030", 7, 6)]
    assert [place[1:] for place in checked] == sorted(place[1:] for place in checked)
    compiled = _places(["compile", str(path), "-o", str(tmp_path / "out"), "-q"])
    assert compiled == checked
