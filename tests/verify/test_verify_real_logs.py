"""Real robot odometry (a Clearpath Husky, 395 s) checked against missions drawn on its route.

The log is read from the ROS bag with ``rosbags`` and written as the CSV a user would export;
the test skips when the shared data or ``rosbags`` is absent.  The regions are placed from the
route's known waypoints (it starts near (8, 0), turns at about (135, -66) and (99, -94), and
crosses (61, -24) at about t = 60 s), not from the verifier's output.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
#: The shared data beside the checkout (or beside the directory of worktrees).
BAG = next(
    (
        base / "shared" / "data" / "bags" / "husky_odometry.bag"
        for base in (ROOT.parent, ROOT.parent.parent)
        if (base / "shared" / "data").is_dir()
    ),
    ROOT.parent / "shared" / "data" / "bags" / "husky_odometry.bag",
)

MISSION = """\
version: 1
name: husky-route
workspace:
  boundary: {rect: [-30, -110, 150, 10]}
regions:
  depot: {rect: [0, -8, 16, 8]}
  east: {rect: [125, -75, 145, -55]}
  south: {rect: [90, -100, 108, -88]}
  pond: {rect: [55, -30, 67, -18]}
robot: {start: [8.3, -0.3], max_speed: 1.5}
task:
  - %s
"""


@pytest.fixture(scope="module")
def husky_csv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if not BAG.exists():
        pytest.skip("shared robot data not present")
    highlevel = pytest.importorskip("rosbags.highlevel")
    rows = []
    with highlevel.AnyReader([BAG]) as reader:
        odometry = [c for c in reader.connections if c.msgtype == "nav_msgs/msg/Odometry"]
        for connection, _, raw in reader.messages(connections=odometry):
            message = reader.deserialize(raw, connection.msgtype)
            stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
            position = message.pose.pose.position
            rows.append((stamp, position.x, position.y))
    samples = np.asarray(rows)
    samples[:, 0] -= samples[0, 0]
    path = tmp_path_factory.mktemp("husky") / "husky.csv"
    np.savetxt(path, samples, delimiter=",", header="t,x,y", comments="")
    return path


def verify(csv: Path, tmp_path: Path, task: str, *flags: str) -> tuple[int, dict[str, object]]:
    mission = tmp_path / "mission.yaml"
    mission.write_text(MISSION % task)
    out, err = io.StringIO(), io.StringIO()
    code = main(["verify", str(csv), "--mission", str(mission), "--json", *flags], out=out, err=err)
    assert err.getvalue() == "", err.getvalue()
    document: dict[str, object] = json.loads(out.getvalue())["result"]
    return code, document


def test_patrol_on_a_real_log_is_inconclusive_with_visits(husky_csv: Path, tmp_path: Path) -> None:
    code, verdict = verify(husky_csv, tmp_path, "patrol depot, east and south")
    assert code == 4
    assert verdict["verdict"] == "inconclusive"
    conjuncts = verdict["conjuncts"]
    assert isinstance(conjuncts, list)
    visits = {c["conjunct"]: c["visits"] for c in conjuncts}
    assert visits == {"G F depot": 1, "G F east": 1, "G F south": 1}


def test_a_done_reach_task_on_a_real_log_is_satisfied(husky_csv: Path, tmp_path: Path) -> None:
    code, verdict = verify(husky_csv, tmp_path, "visit east then south")
    assert (code, verdict["verdict"]) == (0, "satisfied")


def test_an_entry_on_a_real_log_is_violated_with_its_time(husky_csv: Path, tmp_path: Path) -> None:
    code, verdict = verify(husky_csv, tmp_path, "avoid pond")
    assert (code, verdict["verdict"]) == (1, "violated")
    violations = verdict["violations"]
    assert isinstance(violations, list)
    assert len(violations) == 1
    assert 45 < violations[0]["time"] < 65
    # the route enters pond across its west or north side
    x, y = violations[0]["position"]
    assert x == pytest.approx(55, abs=1e-6) or y == pytest.approx(-18, abs=1e-6)


def test_every_violated_conjunct_is_listed(husky_csv: Path, tmp_path: Path) -> None:
    task = "avoid pond\n  - avoid south\n  - visit depot"
    code, verdict = verify(husky_csv, tmp_path, task)
    assert code == 1
    violations = verdict["violations"]
    assert isinstance(violations, list)
    assert {v["conjunct"] for v in violations} == {"G !pond", "G !south"}
    # the old reading: a patrol log that stops outside depot fails it for good
    code, verdict = verify(husky_csv, tmp_path, "patrol depot, east and south", "--assume-stay")
    assert code == 1
