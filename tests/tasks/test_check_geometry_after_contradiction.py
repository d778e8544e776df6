"""`tlmpc check` reports a file's geometry problems also when its task is a contradiction.

A contradiction (T011) is a task problem; a start the body does not fit at (R001) or a region
thinner than the snapping grid (G030) is a workspace problem that `compile` reports at load or
abstraction whatever the task says.  `check` reports every problem of a file, so both.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
from shapely.geometry import Point, box

from tlmpc.cli import main

START_AT_WALL = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 20, 20]}
regions:
  b: {rect: [13, 11, 15, 13]}
robot:
  start: [1.0, 0.09]
  radius: 2
task: [visit b]
ltl: G !b
"""

THIN_REGION = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 10]}
regions:
  a: {rect: [1, 1, 2, 2]}
  thin: [[5, 5], [5.0000000001, 5], [5.0000000001, 6], [5, 6]]
robot: {start: [8, 8]}
task:
  - visit a
  - avoid a
"""


def _check(path: Path) -> list[tuple[str, int | None]]:
    out, err = io.StringIO(), io.StringIO()
    assert main(["check", "--json", str(path)], out=out, err=err) == 1, err.getvalue()
    entry = json.loads(out.getvalue())["result"]["files"][0]
    return [(d["code"], d.get("line")) for d in entry["diagnostics"]]


def _compile_errors(path: Path, out_dir: Path) -> list[tuple[str, int | None]]:
    out, err = io.StringIO(), io.StringIO()
    code = main(
        ["compile", str(path), "-o", str(out_dir), "--until", "abstraction", "--json", "-q"],
        out=out,
        err=err,
    )
    assert code == 1, err.getvalue()
    diagnostics = json.loads(out.getvalue())["diagnostics"]
    return [(d["code"], d.get("line")) for d in diagnostics if d["severity"] == "error"]


@pytest.mark.parametrize(
    ("text", "geometry"),
    [(START_AT_WALL, ("R001", 7)), (THIN_REGION, ("G030", 6))],
    ids=["body-at-start", "thinner-than-grid"],
)
def test_a_contradiction_does_not_hide_the_geometry(
    tmp_path: Path, text: str, geometry: tuple[str, int]
) -> None:
    mission = tmp_path / "mission.yaml"
    mission.write_text(text)
    found = _check(mission)
    assert "T011" in [code for code, _ in found]
    assert geometry in found
    # compile, which never looks at the task's satisfiability before it plans, stops at the
    # same geometry problem: check reports what compile would
    assert _compile_errors(mission, tmp_path / "out") == [geometry]


def test_the_body_problem_is_real() -> None:
    """The oracle for the first case: the start is closer to the wall than the radius."""
    wall = box(0, 0, 20, 20).exterior
    assert Point(1.0, 0.09).distance(wall) < 2
