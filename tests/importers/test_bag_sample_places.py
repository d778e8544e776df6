"""A bag's sample problems (not finite V003, beyond 1e12 V024, a repeated stamp V020) name
the message the sample came from: its topic, its number on the topic and its log time, all
as written into the bag by the test (the oracle), not as the reader reports them."""

from __future__ import annotations

import io
import json
import random
from pathlib import Path
from typing import Any

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
robot: {start: [1, 1], max_speed: 100}
task: [visit a]
"""

SECOND = 1_000_000_000


def verify(*argv: str) -> tuple[int, dict[str, Any]]:
    out = io.StringIO()
    code = main(["verify", *argv, "--json"], out=out, err=io.StringIO())
    return code, json.loads(out.getvalue())


@pytest.fixture
def mission(tmp_path: Path) -> Path:
    path = tmp_path / "mission.yaml"
    path.write_text(MISSION)
    return path


def _bag(tmp_path: Path, kind: str, name: str) -> Path:
    return tmp_path / (f"{name}.bag" if kind == "ros1" else name)


@pytest.mark.parametrize("kind", ["ros1", "sqlite3", "mcap"])
def test_a_bad_sample_names_its_message(tmp_path: Path, mission: Path, kind: str) -> None:
    """Random bags whose stamps are stored out of order, with one bad message: the
    diagnostic names the sample's number in stamp order and the message's topic, number and
    log time in stored order, found by my own sort of what I wrote."""
    rng = random.Random(f"bag-places-{kind}")
    for case in range(4):
        count = rng.randrange(3, 8)
        stamps = [(i + 1) * SECOND + rng.randrange(1000) for i in range(count)]
        rng.shuffle(stamps)  # stored order is not stamp order
        log_times = sorted(rng.sample(range(1, 10**6), count))
        rows = [(ns, rng.uniform(0, 10), rng.uniform(0, 10)) for ns in stamps]
        bad = rng.randrange(count)  # 0-based stored number of the bad message
        problem = ("nan", "huge", "repeat")[case % 3]
        if problem == "nan":
            rows[bad] = (rows[bad][0], float("nan"), rows[bad][2])
        elif problem == "huge":
            rows[bad] = (rows[bad][0], rows[bad][1], 5e13)
        else:
            earlier, bad = sorted(rng.sample(range(count), 2))
            # the later stored of two equal stamps is the repeat: a stable sort puts it second
            rows[bad] = (rows[earlier][0], *rows[bad][1:])
        first_of = {"nan": "V003", "huge": "V024", "repeat": "V020"}
        topic = rng.choice(["/odom", "/robot/pose"])
        path = write_bag(
            _bag(tmp_path, kind, f"case{case}"),
            kind,
            {topic: ("nav_msgs/msg/Odometry", rows)},
            {topic: log_times},
        )
        status, envelope = verify(str(path), "--mission", str(mission))
        assert status == 2, envelope
        (diagnostic,) = envelope["diagnostics"]
        assert diagnostic["code"] == first_of[problem], diagnostic
        # my own stamp order: stable, by integer nanoseconds
        order = sorted(range(count), key=lambda i: rows[i][0])
        sample = order.index(bad)
        expected = (
            f"sample {sample} (pose message {bad + 1} on {topic}, log time {log_times[bad]} ns)"
        )
        assert expected in diagnostic["message"], (expected, diagnostic)
        assert diagnostic["hint"]


def test_a_clean_bag_is_read_once(
    tmp_path: Path, mission: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The messages' log times are looked up only for a diagnostic: a bag with a bad sample
    is opened once more than the same bag without it."""
    opened: list[Path] = []
    real = logs._opened_bag

    def counting(path: Path, *args: Any, **kwargs: Any) -> Any:
        opened.append(path)
        return real(path, *args, **kwargs)

    monkeypatch.setattr(logs, "_opened_bag", counting)
    rows = [(SECOND * (i + 1), 1.0 + i, 1.0 + i) for i in range(4)]
    clean = write_bag(tmp_path / "clean.bag", "ros1", {"/odom": ("nav_msgs/msg/Odometry", rows)})
    status, _ = verify(str(clean), "--mission", str(mission))
    assert status in (0, 1)
    clean_opens = len(opened)
    rows[2] = (rows[2][0], float("inf"), rows[2][2])
    opened.clear()
    broken = write_bag(tmp_path / "bad.bag", "ros1", {"/odom": ("nav_msgs/msg/Odometry", rows)})
    status, envelope = verify(str(broken), "--mission", str(mission))
    assert status == 2
    assert "pose message 3 on /odom" in envelope["diagnostics"][0]["message"]
    assert len(opened) == clean_opens + 1


@pytest.mark.parametrize(("kind", "shuffled"), [("ros1", False), ("mcap", True)])
def test_a_streamed_bad_sample_names_its_message(
    tmp_path: Path, mission: Path, monkeypatch: pytest.MonkeyPatch, kind: str, shuffled: bool
) -> None:
    """The streamed reading (a big bag) names it as the whole reader does, across chunk
    boundaries, in stored order and when the bag has to be read whole and sorted."""
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
    code, document = verify(str(path), "--mission", str(mission))
    assert code == 2
    (diagnostic,) = document["diagnostics"]
    sample = sorted(range(count), key=lambda i: rows[i][0]).index(bad)
    expected = f"sample {sample} (pose message {bad + 1} on /odom, log time {log_times[bad]} ns)"
    assert diagnostic["code"] == "V003"
    assert expected in diagnostic["message"], diagnostic
