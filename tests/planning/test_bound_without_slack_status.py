"""The last status line of `tlmpc compile` prints each time bound with its slack, and a bound
that has none (it occurs on both sides of `<->`: moving it helps one side and hurts the
other) alone, not "by -"."""

from __future__ import annotations

import io
import json
from pathlib import Path

from tlmpc.cli import main

MISSION = """\
version: 1
name: iff
workspace:
  boundary: {rect: [0, 0, 10, 4]}
regions:
  a: {rect: [0, 0, 2, 4]}
  b: {rect: [8, 0, 10, 4]}
robot: {start: [1, 2], max_speed: 1.0}
ltl: "(a <-> F[0,100] b) & F[0,50] b"
"""


def test_a_bound_without_slack_is_printed_alone(tmp_path: Path) -> None:
    path = tmp_path / "iff.yaml"
    path.write_text(MISSION)
    out, err = io.StringIO(), io.StringIO()
    code = main(["compile", str(path), "-o", str(tmp_path / "out")], out=out, err=err)
    assert code == 0, err.getvalue()
    bounds = json.loads((tmp_path / "out" / "summary.json").read_text())["bounds"]
    slacks = {b["bound"]: b["slack"] for b in bounds}
    assert slacks["F[0,100] b"] is None  # under <->: no direction to move it in
    # the robot crosses 6 m to b at 1 m/s at best: F[0,50] b has a positive, finite slack
    assert 0 < slacks["F[0,50] b"] < 44
    shown = out.getvalue() + err.getvalue()
    (status,) = [line for line in shown.splitlines() if "time bounds held" in line]
    assert "by -" not in status
    assert status.endswith(f"F[0,100] b, F[0,50] b by {slacks['F[0,50] b']:.4g} s")
