"""A reactive mission's answer is about its regions as they are, not the mesh's goal cores.

The abstraction stage labels a goal by its core (the region eroded by the goal depth) and an
avoided region, with a margin, by its grown shape.  That is sound for a strategy (the task is
monotone in such a region) but not for "unrealizable": a robot that starts inside a goal,
outside its core, was told that no strategy keeps it there, and a robot with a body that
needs the rim between a wall and a grown region was told that it cannot pass.  The oracles
are geometric: shapely says where the start is and which way is open.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import shapely

from tlmpc.cli import main
from tlmpc.runtime.reactive import ReactiveExecutor

CORRIDOR = """\
version: 1
workspace: {{boundary: {{rect: [0, 0, 4, 2]}}}}
regions:
  r0: {{rect: [0, 0, 2, 2]}}
  r1: {{rect: [3, 0, 4, 2]}}
sensors: {{s: null}}
robot: {{start: [1.95, 1]}}
ltl: "{ltl}"
"""

NARROW = """\
version: 1
workspace: {boundary: {rect: [0, 0, 6, 1]}}
regions:
  r0: {rect: [0, 0, 1, 1]}
  r1: {rect: [2, 0.3, 4, 1]}
  r2: {rect: [5, 0, 6, 1]}
sensors: {s: null}
robot: {start: [0.5, 0.5], radius: 0.2}
task:
  - avoid r1
  - visit r2 infinitely often
  - visit r0 infinitely often
"""


def compile_text(tmp_path: Path, text: str) -> tuple[int, str, Path]:
    source = tmp_path / "m.yaml"
    source.write_text(text)
    out = tmp_path / "out"
    err = io.StringIO()
    code = main(["compile", str(source), "-o", str(out), "-q"], out=io.StringIO(), err=err)
    return code, err.getvalue(), out


def start_inside_r0() -> bool:
    return bool(shapely.box(0, 0, 2, 2).contains(shapely.Point(1.95, 1)))


def test_a_robot_that_starts_in_its_goal_may_stay_there(tmp_path: Path) -> None:
    """Staying at the start meets `G r0` and `G(s -> r0)` whatever the sensor does."""
    assert start_inside_r0()
    for ltl in ("G r0", "G(s -> r0)"):
        code, err, out = compile_text(tmp_path, CORRIDOR.format(ltl=ltl))
        assert code == 0, err
        assert "A030" in err
        strategy = json.loads((out / "strategy.json").read_text())
        labels = strategy["faces"]["labels"]
        starts = {strategy["nodes"][n]["state"]["face"] for n in strategy["initial"]}
        assert all("r0" in labels[f] for f in starts)
        ReactiveExecutor.from_output(out)  # (Q123 unless abstraction.json has its faces)


def test_the_conflict_is_told_on_the_true_regions(tmp_path: Path) -> None:
    """`G(s -> r0) & G(s -> r1)` is unrealizable (r0 and r1 are disjoint); the play shown
    starts where the robot is: in r0, not in a free space outside r0's core."""
    assert start_inside_r0()
    code, err, out = compile_text(tmp_path, CORRIDOR.format(ltl="G(s -> r0) & G(s -> r1)"))
    assert code == 1, err
    assert "Q110" in err
    play = json.loads((out / "counterstrategy.json").read_text())["play"]
    assert play[0]["regions"] == ["r0"]
    abstraction = json.loads((out / "abstraction.json").read_text())
    assert ["r0"] in abstraction["letters"]


def test_a_body_passes_a_narrow_way_the_margin_would_close(tmp_path: Path) -> None:
    """Between the wall (y = 0) and r1 (y >= 0.3) a reference point at y = 0.25 keeps its
    0.2 body off the wall and is outside r1: the way to r2 and back is open."""
    free = shapely.box(0, 0, 6, 1).buffer(-0.2)
    r1 = shapely.box(2, 0.3, 4, 1)
    way = shapely.LineString([(0.5, 0.5), (1.5, 0.25), (4.5, 0.25), (5.5, 0.5)])
    assert free.contains(way)
    assert not way.intersects(r1)
    code, err, out = compile_text(tmp_path, NARROW)
    assert code == 0, err
    assert "R008" in err
    assert (out / "strategy.json").is_file()
    # the margin is the default (the radius), written nowhere: placed where options would be
    # read from, the document's start (not the file name alone)
    (warning,) = [line for line in err.splitlines() if "warning[R008]" in line]
    assert warning.startswith(f"{tmp_path / 'm.yaml'}:1:1: warning[R008]"), warning
