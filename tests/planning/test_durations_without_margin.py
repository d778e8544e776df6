"""A duration (`stay in X for at least T s`) whose goal the margin puts out of reach is planned
without the margin (R008) as a stay, as it is with `margin: 0`: the holding skeleton is tried
on every mesh the planner falls back to, not only on the one with the margin.

Oracles: shapely (the trace ends in a stay inside the dock; the body keeps its radius) and the
stay's length read off the samples, no verifier code.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

from shapely.geometry import LineString, Point, Polygon

from tlmpc.cli import main

# the dock lies against the left wall: the body (radius 0.3) reaches x >= 0.3, the dock's
# inside ends at x = 0.5, so with the default margin (the radius) no path enters it
MISSION = """\
version: 1
name: wall-dock
workspace:
  boundary: {rect: [0, 0, 10, 6]}
regions:
  dock: {rect: [0, 1, 0.5, 4]}
  bay: {rect: [8, 4, 9.5, 5.5]}
robot: {start: [3, 3], max_speed: 1.0, radius: 0.3}
task:
  - visit bay
  - stay in dock for at least 3 s
"""


def _compile(tmp_path: Path, text: str) -> tuple[int, str, Path]:
    mission = tmp_path / "m.yaml"
    mission.write_text(text)
    out = tmp_path / "out"
    err = io.StringIO()
    code = main(["compile", str(mission), "-o", str(out)], io.StringIO(), err)
    return code, err.getvalue(), out


def test_a_duration_out_of_the_margins_reach_is_planned_as_a_stay(tmp_path: Path) -> None:
    code, err, out = _compile(tmp_path, MISSION)
    assert code == 0, err
    assert "warning[R008]" in err
    trace = json.loads((out / "trace.json").read_text())
    assert trace["end"] == "stay"
    dock = Polygon(trace["regions"]["dock"])
    assert dock.covers(Point(trace["points"][-1][1:]))
    free = Polygon(trace["workspace"]["boundary"])
    path = LineString([p[1:] for p in trace["points"]])
    assert path.distance(free.exterior) >= 0.3 - 1e-9
    summary = json.loads((out / "summary.json").read_text())
    assert [b["slack"] for b in summary["bounds"]] == ["inf"]
