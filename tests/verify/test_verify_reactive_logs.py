"""Sensor values from robot logs (CSV columns, bag topics) verified against a reactive mission;
hostile values are located diagnostics; batch and live verification refuse reactive missions.

The expected verdicts follow from the run by hand: the robot crosses the lab (x in [4, 6]) at
1 m/s along y = 1 from t=0, so it is in the lab during [4, 6]."""

from __future__ import annotations

import io
import json
import random
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main

MISSION = """\
version: 1
workspace: {{boundary: {{rect: [0, -1, 10, 3]}}}}
regions:
  lab: {{rect: [4, 0, 6, 2]}}
  goal: {{rect: [8, 0, 10, 2]}}
sensors:
{sensors}
{extra}robot: {{start: [0.5, 1]}}
ltl: "{ltl}"
"""


def mission(
    tmp_path: Path,
    ltl: str = "G(alarm -> !lab) & F goal",
    sensors: str = "  alarm: {column: alarm_on}",
    extra: str = "",
) -> Path:
    path = tmp_path / "m.yaml"
    path.write_text(MISSION.format(ltl=ltl, sensors=sensors, extra=extra))
    return path


def verify(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(["verify", *argv], out=out, err=err), out.getvalue(), err.getvalue()


def result(*argv: str) -> tuple[int, dict[str, Any]]:
    status, out, _ = verify(*argv, "--json")
    return status, json.loads(out)["result"]


def csv_log(tmp_path: Path, rows: list[str], header: str = "t,x,y,alarm_on") -> Path:
    path = tmp_path / "log.csv"
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


ALARM_AT_3 = ["0,0,1,false", "3,3,1,TRUE", "9,9,1,"]


def test_a_bound_column_drives_the_verdict(tmp_path: Path) -> None:
    status, data = result("--mission", str(mission(tmp_path)), str(csv_log(tmp_path, ALARM_AT_3)))
    assert status == 1
    assert data["reactive"]["blame"] == "robot"
    assert data["reactive"]["robot"]["elapsed"] == pytest.approx(4.0)
    assert data["reactive"]["robot"]["part"] == "G(alarm -> !lab)"


def test_values_as_numbers_and_empty_cells(tmp_path: Path) -> None:
    # 1/0, an empty cell keeps the value: the alarm is off over the lab (turned off at 3.5)
    rows = ["0,0,1,1", "3.5,3.5,1,0", "5,5,1,", "9,9,1,"]
    log = str(csv_log(tmp_path, rows))
    status, data = result("--mission", str(mission(tmp_path)), log)
    assert status == 4  # nothing broke; the guarantee's safety part has held so far
    assert data["reactive"]["blame"] is None
    assert verify("--mission", str(mission(tmp_path)), log, "--assume-stay")[0] == 0


def test_an_unbound_sensor_reads_the_column_named_like_it(tmp_path: Path) -> None:
    path = mission(tmp_path, sensors="  alarm: null")
    log = csv_log(tmp_path, ALARM_AT_3, header="time,pose.x,pose.y,Alarm")
    assert verify("--mission", str(path), str(log))[0] == 1


def test_assumptions_from_the_mission(tmp_path: Path) -> None:
    path = mission(tmp_path, extra='assumptions: ["G !alarm"]\n')
    status, data = result("--mission", str(path), str(csv_log(tmp_path, ALARM_AT_3)))
    assert status == 0
    assert data["reactive"]["blame"] == "environment"
    assert data["reactive"]["environment"]["elapsed"] == pytest.approx(3.0)
    assert data["reactive"]["vacuous"] is True
    _, out, _ = verify("--mission", str(path), str(csv_log(tmp_path, ALARM_AT_3)))
    assert "the environment broke an assumption at t=3 s: `G !alarm`" in out
    assert ": satisfied (vacuously: the environment broke an assumption): " in out


def test_times_count_from_the_log_start(tmp_path: Path) -> None:
    rows = ["100,0,1,false", "103,3,1,true", "109,9,1,"]
    status, data = result("--mission", str(mission(tmp_path)), str(csv_log(tmp_path, rows)))
    assert status == 1
    assert data["reactive"]["robot"]["broken_at"] == pytest.approx(104.0)
    assert data["reactive"]["robot"]["elapsed"] == pytest.approx(4.0)


def test_a_logged_action_and_an_unlogged_one(tmp_path: Path) -> None:
    path = mission(tmp_path, ltl="G(alarm -> beep)", extra="actions: {beep: null}\n")
    logged = csv_log(tmp_path, ["0,0,1,0,0", "3,3,1,1,1", "9,9,1,,"], "t,x,y,alarm_on,beep")
    assert verify("--mission", str(path), str(logged))[0] == 4  # held so far
    late = csv_log(
        tmp_path, ["0,0,1,0,0", "3,3,1,1,", "4,4,1,,1", "9,9,1,,"], "t,x,y,alarm_on,beep"
    )
    status, data = result("--mission", str(path), str(late))
    assert status == 1
    assert data["reactive"]["robot"]["elapsed"] == pytest.approx(3.0)
    # no beep column: the action is unknown, so nothing can be decided
    unlogged = csv_log(tmp_path, ["0,0,1,0", "3,3,1,1", "9,9,1,"])
    assert verify("--mission", str(path), str(unlogged))[0] == 4


@pytest.mark.parametrize(
    ("rows", "code", "line"),
    [
        (["0,0,1,false", "3,3,1,maybe", "9,9,1,"], "V030", 3),
        (["0,0,1,false", "3,3,1,2", "9,9,1,"], "V030", 3),
        (["0,0,1,false", "3,3,1,nan", "9,9,1,"], "V030", 3),
        (["0,0,1,false", "3,3,1,true", "2,9,1,"], "V005", 4),
        (["0,0,1,false", "3,3,1,true", "3,9,1,false"], "V020", 4),
    ],
)
def test_hostile_sensor_cells_are_located(
    tmp_path: Path, rows: list[str], code: str, line: int
) -> None:
    log = csv_log(tmp_path, rows)
    status, out, err = verify("--mission", str(mission(tmp_path)), str(log), "--json")
    assert status == 2
    assert "Traceback" not in err
    found = json.loads(out)["diagnostics"][0]
    assert (found["code"], found["line"], found["file"]) == (code, line, str(log))


def test_a_missing_sensor_column_is_a_diagnostic(tmp_path: Path) -> None:
    log = csv_log(tmp_path, ["0,0,1,0", "9,9,1,0"], header="t,x,y,siren")
    status, _, err = verify("--mission", str(mission(tmp_path)), str(log))
    assert status == 2
    assert "error[V032]" in err
    assert "alarm_on" in err
    assert "t, x, y, siren" in err


def test_a_log_without_header_cannot_carry_sensors(tmp_path: Path) -> None:
    log = tmp_path / "log.csv"
    log.write_text("0 0 1\n9 9 1\n")
    status, _, err = verify("--mission", str(mission(tmp_path)), str(log))
    assert status == 2
    assert "error[V032]" in err


# -- bags --------------------------------------------------------------------------------------


def write_bag(
    path: Path,
    kind: str,
    poses: list[tuple[int, float, float]],
    bools: dict[str, list[tuple[int, Any]]],
    *,
    bool_type: str = "std_msgs/msg/Bool",
) -> Path:
    """A bag of ``kind`` ros1 / sqlite3 / mcap: PoseStamped on /pose, and per topic
    ``std_msgs/Bool`` (or ``bool_type``: Int32, String) messages at (log time ns, value)."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if kind != "ros1" else Stores.ROS1_NOETIC)
    types: Any = store.types
    time_type = types["builtin_interfaces/msg/Time"]
    header = types["std_msgs/msg/Header"]

    def pose(ns: int, x: float, y: float) -> Any:
        stamp = time_type(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
        head = (
            header(seq=0, stamp=stamp, frame_id="map")
            if kind == "ros1"
            else header(stamp=stamp, frame_id="map")
        )
        point = types["geometry_msgs/msg/Point"](x=x, y=y, z=0.0)
        turn = types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
        body = types["geometry_msgs/msg/Pose"](position=point, orientation=turn)
        return types["geometry_msgs/msg/PoseStamped"](header=head, pose=body)

    messages: list[tuple[str, str, int, Any]] = [
        ("/pose", "geometry_msgs/msg/PoseStamped", ns, pose(ns, x, y)) for ns, x, y in poses
    ]
    for topic, samples in bools.items():
        messages += [(topic, bool_type, ns, types[bool_type](data=v)) for ns, v in samples]
    serialize = store.serialize_ros1 if kind == "ros1" else store.serialize_cdr
    if kind == "ros1":
        from rosbags.rosbag1 import Writer as Writer1

        with Writer1(path) as writer1:
            kinds1 = {t: m for t, m, _, _ in messages}
            links = {t: writer1.add_connection(t, m, typestore=store) for t, m in kinds1.items()}
            for topic, msgtype, ns, message in sorted(messages, key=lambda m: m[2]):
                writer1.write(links[topic], ns, serialize(message, msgtype))
        return path
    from rosbags.rosbag2 import StoragePlugin, Writer

    plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        kinds2 = {t: m for t, m, _, _ in messages}
        links2 = {t: writer.add_connection(t, m, typestore=store) for t, m in kinds2.items()}
        for topic, msgtype, ns, message in sorted(messages, key=lambda m: m[2]):
            writer.write(links2[topic], ns, serialize(message, msgtype))
    return path


SECOND = 1_000_000_000
POSES = [(0, 0.0, 1.0), (3 * SECOND, 3.0, 1.0), (9 * SECOND, 9.0, 1.0)]


@pytest.mark.parametrize("kind", ["ros1", "sqlite3", "mcap"])
def test_bag_topics_drive_the_verdict(tmp_path: Path, kind: str) -> None:
    pytest.importorskip("rosbags")
    bag = write_bag(
        tmp_path / ("run.bag" if kind == "ros1" else "run"),
        kind,
        POSES,
        {"/alarm": [(0, False), (3 * SECOND, True)]},
    )
    path = mission(tmp_path, sensors="  alarm: null")
    status, data = result("--mission", str(path), str(bag))
    assert status == 1
    assert data["reactive"]["robot"]["elapsed"] == pytest.approx(4.0)
    # bound to another topic and field, where the alarm stays off
    other = write_bag(
        tmp_path / ("other.bag" if kind == "ros1" else "other"),
        kind,
        POSES,
        {"/alarm": [(0, True)], "/safety/siren": [(0, False)]},
    )
    bound = mission(tmp_path, sensors="  alarm: {topic: /safety/siren, field: data}")
    assert verify("--mission", str(bound), str(other), "--assume-stay")[0] == 0


def test_bag_sensor_stamps_a_nanosecond_apart_are_not_repeated(tmp_path: Path) -> None:
    # At a real epoch ns / 1e9 rounds stamps 1 ns apart to one float (a float second's step
    # is 238 ns there): two samples of the alarm must stay two times, not a repeat (V031).
    # Bool messages have no header: their log times stamp them.
    pytest.importorskip("rosbags")
    epoch = 1_700_000_000 * SECOND
    poses = [(epoch + ns, x, y) for ns, x, y in POSES]
    alarm = [(epoch, False), (epoch + 3 * SECOND, False), (epoch + 3 * SECOND + 1, True)]
    bag = write_bag(tmp_path / "run.bag", "ros1", poses, {"/alarm": alarm})
    path = mission(tmp_path, sensors="  alarm: null")
    status, data = result("--mission", str(path), str(bag))
    assert status == 1  # the alarm is on from t = 3 s, and the robot enters the lab at 4 s
    assert data["reactive"]["robot"]["elapsed"] == pytest.approx(4.0)
    # a stamp truly repeated is still refused
    twice = write_bag(
        tmp_path / "twice.bag", "ros1", poses, {"/alarm": [*alarm, (epoch + 3 * SECOND + 1, True)]}
    )
    status, out, _ = verify("--mission", str(path), str(twice), "--json")
    assert status == 2
    assert json.loads(out)["diagnostics"][0]["code"] == "V031"


def test_bag_hostile_values_and_missing_topics(tmp_path: Path) -> None:
    pytest.importorskip("rosbags")
    unbound = mission(tmp_path, sensors="  alarm: null")
    numbers = write_bag(
        tmp_path / "n.bag",
        "ros1",
        POSES,
        {"/alarm": [(0, 0), (SECOND, 7)]},
        bool_type="std_msgs/msg/Int32",
    )
    status, out, err = verify("--mission", str(unbound), str(numbers), "--json")
    assert status == 2
    assert "Traceback" not in err
    found = json.loads(out)["diagnostics"][0]
    assert found["code"] == "V030"
    assert "sample 1 (message 2 on /alarm, log time 1000000000 ns)" in found["message"]
    missing = write_bag(tmp_path / "m.bag", "ros1", POSES, {"/siren": [(0, False)]})
    status, _, err = verify("--mission", str(unbound), str(missing))
    assert status == 2
    assert "error[V032]" in err
    assert "/siren" in err  # the topics are listed
    fieldless = mission(tmp_path, sensors="  alarm: {topic: /siren, field: level}")
    status, _, err = verify("--mission", str(fieldless), str(missing))
    assert status == 2
    assert "error[V035]" in err


# -- many logs, streams and live monitoring refuse reactive missions -----------------------------


def test_batch_and_monitor_refuse_a_reactive_mission(tmp_path: Path) -> None:
    path = mission(tmp_path)
    log = csv_log(tmp_path, ALARM_AT_3)
    status, out, _ = verify("--mission", str(path), str(log), str(log), "--no-cache")
    assert status == 2
    assert "error[U110]" in out
    monitor_out, monitor_err = io.StringIO(), io.StringIO()
    status = main(["monitor", "--mission", str(path), str(log)], out=monitor_out, err=monitor_err)
    assert status == 2
    assert "error[U110]" in monitor_err.getvalue()


def test_bag_strings_and_repeated_stamps(tmp_path: Path) -> None:
    pytest.importorskip("rosbags")
    unbound = mission(tmp_path, sensors="  alarm: null")
    words = {"/alarm": [(0, "false"), (3 * SECOND, "True")]}
    strings = write_bag(tmp_path / "s.bag", "ros1", POSES, words, bool_type="std_msgs/msg/String")
    status, data = result("--mission", str(unbound), str(strings))
    assert status == 1
    assert data["reactive"]["robot"]["elapsed"] == pytest.approx(4.0)
    twice = {"/alarm": [(0, False), (SECOND, True), (SECOND, False)]}
    repeated = write_bag(tmp_path / "r.bag", "ros1", POSES, twice)
    status, out, _ = verify("--mission", str(unbound), str(repeated), "--json")
    assert status == 2
    found = json.loads(out)["diagnostics"][0]
    assert found["code"] == "V031"
    assert "sample 2 (message 3 on /alarm, log time 1000000000 ns)" in found["message"]


def test_a_sensor_topic_missing_messages_is_refused(tmp_path: Path) -> None:
    # a bag whose metadata declares more alarm messages than it holds: read as it is, the
    # alarm would stay off where the robot logged it on
    import yaml

    pytest.importorskip("rosbags")
    bag = write_bag(tmp_path / "run", "mcap", POSES, {"/alarm": [(0, False), (3 * SECOND, True)]})
    metadata = bag / "metadata.yaml"
    information = yaml.safe_load(metadata.read_text())
    topics = information["rosbag2_bagfile_information"]["topics_with_message_count"]
    (alarm,) = [t for t in topics if t["topic_metadata"]["name"] == "/alarm"]
    alarm["message_count"] += 1
    metadata.write_text(yaml.safe_dump(information))
    path = mission(tmp_path, sensors="  alarm: null")
    status, _, err = verify("--mission", str(path), str(bag))
    assert status == 2, err
    assert "error[M065]" in err
    assert "declares 3 messages on /alarm (metadata.yaml), but 2 could be read" in err


@pytest.mark.parametrize("kind", ["ros1", "mcap"])
def test_a_refused_bag_sensor_sample_names_its_message(tmp_path: Path, kind: str) -> None:
    """A sensor's bad sample in a bag (V030 not a boolean, V031 a repeated stamp) names its
    message: the topic, its number there and its log time, as written here."""
    pytest.importorskip("rosbags")
    rng = random.Random(f"signal-{kind}")
    path = mission(tmp_path, sensors="  alarm: null")
    for case in range(4):
        count = rng.randrange(3, 7)
        times = sorted(rng.sample(range(1, 5 * SECOND), count))
        values: list[Any] = [rng.choice([0, 1]) for _ in range(count)]
        bad = rng.randrange(1, count)
        if case % 2:  # a repeated log time (a Bool has no header: its log time stamps it)
            times[bad] = times[bad - 1]
            code = "V031"
        else:
            values[bad] = rng.choice([2, 7, -1])
            code = "V030"
        bag = write_bag(
            tmp_path / (f"s{case}.bag" if kind == "ros1" else f"s{case}"),
            kind,
            POSES,
            {"/alarm": list(zip(times, values, strict=True))},
            bool_type="std_msgs/msg/Int32",
        )
        status, out, _ = verify("--mission", str(path), str(bag), "--json")
        assert status == 2
        (diagnostic,) = json.loads(out)["diagnostics"]
        assert diagnostic["code"] == code
        expected = f"sample {bad} (message {bad + 1} on /alarm, log time {times[bad]} ns)"
        assert expected in diagnostic["message"], (expected, diagnostic)
