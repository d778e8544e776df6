"""The streamed reading of a bag (``tlmpc fleet``, ``tlmpc verify`` of a big bag) names the
message of a bad sample as the whole reader does: its topic, number on the topic and log
time, as written into the bag by the test, across chunk boundaries, in stored order and
when the bag has to be read whole and sorted."""

from __future__ import annotations

import io
import json
import random
from pathlib import Path

import pytest
from robot_data import write_bag

from tlmpc.cli import main
from tlmpc.importers import logs

pytest.importorskip("rosbags")

MISSION = """\
version: 1
workspace: {boundary: {rect: [0, 0, 10, 10]}}
regions:
  a: {rect: [2, 2, 4, 4]}
robot: {start: [1, 1], max_speed: 1000000}
task: [visit a]
"""


@pytest.mark.parametrize(("kind", "shuffled"), [("ros1", False), ("mcap", True)])
def test_a_streamed_bad_sample_names_its_message(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str, shuffled: bool
) -> None:
    monkeypatch.setattr(logs, "BAG_STREAM_FROM", 0)  # every bag streams
    rng = random.Random(f"stream-{kind}")
    count = logs.BAG_CHUNK + 50  # two chunks
    stamps = [(i + 1) * 1_000_000 for i in range(count)]
    if shuffled:  # out of order: read again whole and sorted
        stamps[-2], stamps[5] = stamps[5], stamps[-2]
    log_times = [(i + 1) * 1_000 + rng.randrange(999) for i in range(count)]
    rows = [(ns, 5.0, 5.0) for ns in stamps]
    bad = count - 3  # in the second chunk
    rows[bad] = (rows[bad][0], float("nan"), 5.0)
    path = tmp_path / ("log.bag" if kind == "ros1" else "log")
    write_bag(path, kind, {"/odom": ("nav_msgs/msg/Odometry", rows)}, {"/odom": log_times})
    mission = tmp_path / "mission.yaml"
    mission.write_text(MISSION)
    out = io.StringIO()
    argv = ["verify", str(path), "--mission", str(mission), "--json"]
    assert main(argv, out=out, err=io.StringIO()) == 2
    (diagnostic,) = json.loads(out.getvalue())["diagnostics"]
    sample = sorted(range(count), key=lambda i: rows[i][0]).index(bad)
    expected = f"sample {sample} (pose message {bad + 1} on /odom, log time {log_times[bad]} ns)"
    assert diagnostic["code"] == "V003"
    assert expected in diagnostic["message"], diagnostic
