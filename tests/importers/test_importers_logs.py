"""Logs in: flexible CSV and ROS 1 / ROS 2 (sqlite3, MCAP) / .mcap bags give the same samples."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from robot_data import require_shared, write_bag

from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.importers.logs import read_log, stamp_seconds
from tlmpc.verify.samples import check_samples

POSE_TYPES = (
    "nav_msgs/msg/Odometry",
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
)
KINDS = ("ros1", "sqlite3", "mcap")

MISSION = """\
version: 1
workspace: {boundary: {rect: [-5, -5, 5, 5]}}
regions:
  a: {rect: [0.5, -1, 1.5, 1]}
  b: {rect: [-3, -3, -2, -2]}
robot: {start: [0, 0]}
task: [visit a, avoid b]
"""


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


def bag_path(tmp_path: Path, kind: str, name: str = "log") -> Path:
    return tmp_path / (f"{name}.bag" if kind == "ros1" else name)


ROWS = [(2_000_000_000 + 100_000_000 * i, 0.25 * i, 0.1 * i - 0.3) for i in range(9)]


def expected(rows: list[tuple[int, float, float]]) -> np.ndarray:
    return np.array([[ns / 1e9, x, y] for ns, x, y in rows])


# --- CSV ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "text",
    [
        "t,x,y\n0,1,2\n1,3,4\n",
        "time,x,y\n0,1,2\n1,3,4\n",
        "# recorded by a robot\nTime, X, Y, heading\n0, 1, 2, 0.5\n# pause\n\n1, 3, 4, 0.7\n",
        "time;x;y\n0;1;2\n1;3;4\n",
        "time\tx\ty\tv\n0\t1\t2\t9\n1\t3\t4\t9\n",
        "time x y\n0 1 2\n1 3 4\n",
        "0,1,2\n1,3,4\n",
        "x,y,stamp\n1,2,0\n3,4,1\n",
        "time,x,y,2\n0,1,2,9\n1,3,4,9\n",  # a header is any line with a non-number
        "field.header.stamp,field.pose.position.x,field.pose.position.y\n0,1,2\n1,3,4\n",
    ],
)
def test_csv_forms_give_the_same_samples(tmp_path: Path, text: str) -> None:
    path = tmp_path / "log.csv"
    path.write_text(text)
    assert read_log(path).samples.tolist() == [[0.0, 1.0, 2.0], [1.0, 3.0, 4.0]]


def test_columns_choose_by_name_and_number(tmp_path: Path) -> None:
    path = tmp_path / "log.csv"
    path.write_text("stamp,gx,gy,px,py\n0,9,9,1,2\n1,9,9,3,4\n")
    assert read_log(path, columns=("stamp", "px", "py")).samples.tolist() == [
        [0.0, 1.0, 2.0],
        [1.0, 3.0, 4.0],
    ]
    assert read_log(path, columns=("1", "4", "5")).samples.tolist() == [
        [0.0, 1.0, 2.0],
        [1.0, 3.0, 4.0],
    ]
    bare = tmp_path / "bare.csv"
    bare.write_text("0,9,1,2\n1,9,3,4\n")
    assert read_log(bare, columns=("1", "3", "4")).samples.tolist() == [
        [0.0, 1.0, 2.0],
        [1.0, 3.0, 4.0],
    ]


@pytest.mark.parametrize(
    ("text", "columns", "needle", "line"),
    [
        ("0,1,2,3\n", None, "4 columns", 1),
        ("time,a,b\n0,1,2\n", None, "no x column", 1),
        ("t,x,y\n0,1,2\n1,oops,3\n", None, "not a number", 3),
        ("t,x,y\n0,1,2\n1_0,1,3\n", None, "not a number", 3),  # Python's float takes it
        ("t,x,y\n0,1\n", None, "expected at least 3", 2),
        ("t,x,y\n0,1,2\n", ("t", "x", "z"), "no column named 'z'", 1),
        ("0,1,2\n", ("t", "x", "y"), "must give column numbers", 1),
        ("t,x,y\n0,1,2\n", ("1", "2", "7"), "column 7 does not exist", 1),
        ("t,pos_x,goal_x,y\n0,1,2,3\n", None, "several columns could be x", 1),
    ],
)
def test_bad_csv_gets_a_located_diagnostic(
    tmp_path: Path, text: str, columns: tuple[str, str, str] | None, needle: str, line: int
) -> None:
    path = tmp_path / "log.csv"
    path.write_text(text)
    with pytest.raises(UsageError) as caught:
        read_log(path, columns=columns)
    diagnostic = caught.value.diagnostics[0]
    assert needle in diagnostic.message
    assert diagnostic.line == line
    assert diagnostic.code.startswith("M05")


finite = st.floats(-1e6, 1e6, allow_nan=False)


@given(
    rows=st.lists(st.tuples(finite, finite, finite, finite), min_size=1, max_size=20),
    separator=st.sampled_from([",", ";", "\t", " "]),
    names=st.sampled_from([("t", "x", "y"), ("time", "x", "y"), ("TIME", "X", "Y")]),
    extra_first=st.booleans(),
    comment=st.booleans(),
)
def test_csv_round_trips_exactly(
    tmp_path_factory: pytest.TempPathFactory,
    rows: list[tuple[float, float, float, float]],
    separator: str,
    names: tuple[str, str, str],
    extra_first: bool,
    comment: bool,
) -> None:
    header = list(names)
    if extra_first:
        header = ["speed", *header]
    lines = [separator.join(header)]
    for t, x, y, v in rows:
        cells = [repr(t), repr(x), repr(y)]
        lines.append(separator.join([repr(v), *cells] if extra_first else [*cells, repr(v)]))
    if not extra_first:
        lines[0] = separator.join([*header, "speed"])
    if comment:
        lines.insert(1, "# a comment line")
    path = tmp_path_factory.mktemp("csv") / "log.csv"
    path.write_text("\n".join(lines) + "\n")
    got = read_log(path).samples
    assert got.tolist() == [[t, x, y] for t, x, y, _ in rows]


# --- bags ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("msgtype", POSE_TYPES)
def test_bags_in_every_storage_give_the_logged_poses(
    tmp_path: Path, kind: str, msgtype: str
) -> None:
    path = write_bag(
        bag_path(tmp_path, kind),
        kind,
        {"/pose": (msgtype, ROWS), "/chatter": ("std_msgs/msg/String", ROWS[:3])},
    )
    log = read_log(path)
    assert log.topic == "/pose"
    assert np.array_equal(log.samples, expected(ROWS))


def test_a_bare_mcap_file_and_a_db3_file_read_like_their_bags(tmp_path: Path) -> None:
    mcap_bag = write_bag(tmp_path / "m", "mcap", {"/odom": (POSE_TYPES[0], ROWS)})
    sqlite_bag = write_bag(tmp_path / "s", "sqlite3", {"/odom": (POSE_TYPES[0], ROWS)})
    (mcap_file,) = mcap_bag.glob("*.mcap")
    (db3_file,) = sqlite_bag.glob("*.db3")
    assert np.array_equal(read_log(mcap_file).samples, expected(ROWS))
    assert np.array_equal(read_log(db3_file).samples, expected(ROWS))


@pytest.mark.parametrize("kind", KINDS)
def test_stamps_are_sorted_and_repeats_refused_like_csv(tmp_path: Path, kind: str) -> None:
    # Received in this order (log times increase) but stamped out of order, one stamp twice.
    repeat = (ROWS[1][0], 9.0, 9.0)
    rows = [ROWS[2], ROWS[0], ROWS[1], repeat]
    received = [5_000_000_000 + i for i in range(len(rows))]
    path = write_bag(
        bag_path(tmp_path, kind),
        kind,
        {"/odom": (POSE_TYPES[0], rows)},
        log_times={"/odom": received},
    )
    samples = read_log(path).samples
    # sorted by stamp, the repeat kept after its twin (arrival order): neither is hidden
    assert np.array_equal(samples, expected([ROWS[0], ROWS[1], repeat, ROWS[2]]))
    # ... and refused as the same rows in a CSV are
    csv = tmp_path / "log.csv"
    in_order = [ROWS[0], ROWS[1], repeat, ROWS[2]]
    csv.write_text("t,x,y\n" + "".join(f"{r[0] / 1e9!r},{r[1]!r},{r[2]!r}\n" for r in in_order))
    for log in (samples, read_log(csv).samples):
        with pytest.raises(UsageError) as caught:
            check_samples(log[:, 0], log[:, 1], log[:, 2], file="log")
        assert [d.code for d in caught.value.diagnostics] == ["V020"]


#: A real epoch in nanoseconds (2023): a float second's step there is 238 ns.
EPOCH = 1_700_000_000 * 1_000_000_000


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("clock", ["header stamp", "log time"])
def test_stamps_a_nanosecond_apart_stay_apart(tmp_path: Path, kind: str, clock: str) -> None:
    # Distinct integer stamps 1 ns apart, which ns / 1e9 rounds to one float: not repeated.
    # "log time": the header stamps are zero, so each pose takes its log (receive) time.
    stamps = [EPOCH + i for i in range(5)] + [EPOCH + 1_000_000_000]
    rows = [(ns if clock == "header stamp" else 0, 0.1 * i, 0.0) for i, ns in enumerate(stamps)]
    path = write_bag(
        bag_path(tmp_path, kind), kind, {"/odom": (POSE_TYPES[0], rows)}, {"/odom": stamps}
    )
    samples = read_log(path).samples
    assert np.all(np.diff(samples[:, 0]) > 0)  # in the stamps' order, each its own time
    check_samples(samples[:, 0], samples[:, 1], samples[:, 2], file="log")  # no V020
    assert samples[0, 0] == EPOCH / 1e9
    assert samples[-1, 0] == (EPOCH + 1_000_000_000) / 1e9  # far apart: as a CSV has it
    # each a float step after the one before (238 ns: as close as float seconds can be)
    assert np.array_equal(np.diff(samples[:5, 0]), np.full(4, np.spacing(EPOCH / 1e9)))
    # a stamp that is truly repeated is still refused
    twice = [*rows[:3], (rows[2][0], 9.0, 9.0)]
    repeated = write_bag(
        bag_path(tmp_path, kind, "twice"),
        kind,
        {"/odom": (POSE_TYPES[0], twice)},
        {"/odom": [*stamps[:3], stamps[2]]},
    )
    log = read_log(repeated).samples
    with pytest.raises(UsageError) as caught:
        check_samples(log[:, 0], log[:, 1], log[:, 2], file="log")
    assert [d.code for d in caught.value.diagnostics] == ["V020"]


@settings(max_examples=200, deadline=None)
@example(start=EPOCH, gaps=[1, 0, 1, 300, 1, 10**9], cut=2)
@given(
    start=st.integers(-(2**62), 2**62) | st.integers(10**18, 4 * 10**18),  # ROS epochs
    gaps=st.lists(st.integers(0, 400) | st.integers(0, 10**10), max_size=40),
    cut=st.integers(0, 40),
)
def test_stamp_seconds_keep_the_stamps_order_and_ties(
    start: int, gaps: list[int], cut: int
) -> None:
    stamps = np.array([start + sum(gaps[:k]) for k in range(len(gaps) + 1)], dtype=np.int64)
    seconds = stamp_seconds(stamps)
    steps = np.diff(stamps)
    assert np.array_equal(np.diff(seconds) > 0, steps > 0)  # later stamps later, ties tied
    assert np.array_equal(np.diff(seconds) == 0, steps == 0)
    naive = stamps / 1e9
    if np.array_equal(np.diff(naive) > 0, steps > 0):
        assert np.array_equal(seconds, naive)  # nothing collapsed: exactly ns / 1e9
    # the oracle, one stamp at a time: a tie keeps the time before, a later stamp gets its
    # ns / 1e9, or the next float after the time before when that is not later
    oracle = [float(naive[0])] if len(stamps) else []
    for step, value in zip(steps.tolist(), naive[1:].tolist(), strict=True):
        after = float(np.nextafter(oracle[-1], np.inf))
        oracle.append(oracle[-1] if step == 0 else max(value, after))
    assert seconds.tolist() == oracle
    # a stream's chunks, each after the one before, give the same seconds
    cut = min(cut, len(stamps))
    head = stamp_seconds(stamps[:cut])
    previous = (int(stamps[cut - 1]), float(head[-1])) if cut else None
    tail = stamp_seconds(stamps[cut:], previous)
    assert np.array_equal(np.concatenate([head, tail]), seconds)


def test_transform_maps_the_log_frame(tmp_path: Path) -> None:
    path = write_bag(bag_path(tmp_path, "mcap"), "mcap", {"/odom": (POSE_TYPES[0], ROWS)})
    moved = read_log(path, transform=(1.0, -2.0, np.pi / 2)).samples
    base = expected(ROWS)
    assert np.allclose(moved[:, 1], -base[:, 2] + 1.0)
    assert np.allclose(moved[:, 2], base[:, 1] - 2.0)


def test_ambiguous_missing_and_wrong_topics_are_explained(tmp_path: Path) -> None:
    two = write_bag(
        bag_path(tmp_path, "ros1", "two"),
        "ros1",
        {"/odom": (POSE_TYPES[0], ROWS), "/amcl_pose": (POSE_TYPES[2], ROWS)},
    )
    with pytest.raises(UsageError) as caught:
        read_log(two)
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == "M064"
    assert diagnostic.hint is not None
    assert "/odom" in diagnostic.hint
    assert "/amcl_pose" in diagnostic.hint
    assert np.array_equal(read_log(two, topic="/amcl_pose").samples, expected(ROWS))
    with pytest.raises(UsageError) as caught:
        read_log(two, topic="/nope")
    assert caught.value.diagnostics[0].code == "M062"
    none = write_bag(
        bag_path(tmp_path, "sqlite3", "none"), "sqlite3", {"/chat": ("std_msgs/msg/String", ROWS)}
    )
    with pytest.raises(UsageError) as caught:
        read_log(none)
    assert caught.value.diagnostics[0].code == "M061"
    with pytest.raises(UsageError) as caught:
        read_log(none, topic="/chat")
    assert caught.value.diagnostics[0].code == "M063"


@pytest.mark.parametrize("suffix", [".bag", ".mcap"])
def test_a_corrupt_bag_gets_a_diagnostic_not_a_traceback(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"broken{suffix}"
    path.write_bytes(b"\x00garbage" * 50)
    (tmp_path / "m.yaml").write_text(MISSION)
    code, _, err = run("verify", str(path), "--mission", str(tmp_path / "m.yaml"))
    assert code == 2
    assert "error[M060]" in err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("form", "keep", "expected"),
    [
        # ends right after its magic, where rosbags' reader raised a bare TypeError (ord())
        ("mcap file", 8, "is truncated: it ends at byte 8, where record 1 should begin"),
        ("mcap file", 20, "truncated or corrupt: record 1 (header, at byte 8) declares 26 bytes"),
        ("mcap file", 100, "is truncated or corrupt: record 2 (chunk, at byte"),
        ("mcap bag", 8, "the file (log.mcap) is truncated: it ends at byte 8"),
        ("ros1", 4000, "is truncated or corrupt: record 1 (bag header, at byte 13) declares"),
        ("ros1", -20, "is truncated"),
    ],
)
def test_a_truncated_bag_says_where_it_ends(
    tmp_path: Path, form: str, keep: int, expected: str
) -> None:
    kind = form.split()[0]
    bag = write_bag(bag_path(tmp_path, kind), kind, {"/odom": (POSE_TYPES[0], ROWS)})
    data = next(iter(bag.glob("*.mcap"))) if form.startswith("mcap") else bag
    data.write_bytes(data.read_bytes()[:keep])
    path = data if form == "mcap file" else bag
    with pytest.raises(UsageError) as caught:
        read_log(path)
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == "M060"
    assert expected in diagnostic.message
    assert "Error" not in diagnostic.message  # no Python exception's name or text
    assert diagnostic.hint is not None
    assert "cut short" in diagnostic.hint


def test_a_symbolic_link_loop_is_named_as_one(tmp_path: Path) -> None:
    mission = tmp_path / "m.yaml"
    mission.write_text(MISSION)
    loop = tmp_path / "self.bag"
    loop.symlink_to(loop.name)  # a link to itself
    code, _, err = run("verify", str(loop), "--mission", str(mission))
    assert code == 2
    assert "error[M050]" in err
    assert "it is a symbolic link loop" in err
    assert "no such file" not in err
    # a folder of logs that is a link loop: no "artifact", no bare strerror
    folder = tmp_path / "logs"
    folder.symlink_to(folder.name)
    code, _, err = run("verify", str(folder), "--mission", str(mission))
    assert code == 2
    assert "error[U001]" in err
    assert "it is a symbolic link loop" in err
    assert "artifact" not in err
    # verified with others, each says so in its line
    code, out, _ = run("verify", str(folder), str(loop), "--mission", str(mission), "--no-cache")
    assert code == 2
    assert out.count("it is a symbolic link loop") == 2
    # a link to nothing, and a plain missing file
    dangling = tmp_path / "gone.mcap"
    dangling.symlink_to("nowhere.mcap")
    code, _, err = run("verify", str(dangling), "--mission", str(mission))
    assert "symbolic link to nowhere.mcap, which does not exist" in err
    code, _, err = run("verify", str(tmp_path / "missing.bag"), "--mission", str(mission))
    assert "error[M050]" in err
    assert "no such file or directory" in err


def test_verify_gives_identical_verdicts_for_every_form(tmp_path: Path) -> None:
    mission = tmp_path / "m.yaml"
    mission.write_text(MISSION)
    rows = [(1_000_000_000 + 200_000_000 * i, -0.5 + 0.2 * i, 0.05 * i) for i in range(12)]
    paths = [
        write_bag(bag_path(tmp_path, k, k), k, {"/odom": (POSE_TYPES[0], rows)}) for k in KINDS
    ]
    csv = tmp_path / "log.csv"
    csv.write_text(
        "# exported\ntime;x;y;v\n" + "".join(f"{ns / 1e9!r};{x!r};{y!r};0\n" for ns, x, y in rows)
    )
    verdicts = []
    for path in [*paths, csv]:
        code, out, err = run(
            "verify", str(path), "--mission", str(mission), "--json", "--assume-stay"
        )
        assert code == 0, err
        verdicts.append(json.loads(out)["result"])
    assert all(v == verdicts[0] for v in verdicts)
    assert verdicts[0]["satisfied"] is True


def test_verify_flags_reach_the_reader(tmp_path: Path) -> None:
    mission = tmp_path / "m.yaml"
    mission.write_text(MISSION)
    csv = tmp_path / "log.csv"
    csv.write_text("stamp,a,b\n0,-3,0\n1,-1,0\n2,1,0\n")
    code, _, err = run(
        "verify", str(csv), "--mission", str(mission), "--columns", "stamp,a,b", "--assume-stay"
    )
    assert code == 0, err
    code, _, err = run("verify", str(csv), "--mission", str(mission), "--columns", "stamp,a")
    assert code == 2
    assert "error[M051]" in err
    code, _, err = run(
        "verify", str(csv), "--mission", str(mission), "--columns", "1,2,3", "--transform", "0,9,0"
    )
    assert code == 1  # moved 9 up: never in a
    code, _, err = run("verify", str(csv), "--mission", str(mission), "--topic", "/odom")
    assert code == 2
    assert "error[M058]" in err


# --- the real robot bags --------------------------------------------------------------------------

REAL_FORMS = (
    "bags/jackal_odometry.bag",
    "bags/jackal_odometry_ros2_sqlite3",
    "bags/jackal_odometry_ros2_mcap",
    "bags/jackal_odometry_ros2_mcap/rl_test2_mcap.mcap",
)

#: Held-out missions over the Jackal's odometry frame (written without looking at the verdicts).
HELD_OUT = {
    "patrol": "task: [visit far then return to home]\n",
    "stay_near": "task: [always stay in arena]\n",
    "avoid_pit": "task: [visit far, avoid pit]\n",
}
REGIONS = (
    "regions:\n  home: {rect: [-1, -1, 1, 1]}\n  far: {rect: [3, -2, 6, 2]}\n"
    "  arena: {rect: [-10, -10, 10, 10]}\n  pit: {rect: [1.5, -0.5, 2.5, 0.5]}\n"
)


def test_real_bag_forms_and_their_csv_agree(tmp_path: Path) -> None:
    paths = [require_shared(form) for form in REAL_FORMS]
    logs = [read_log(p) for p in paths]
    reference = logs[0].samples
    assert len(reference) == 3060
    for log in logs[1:]:
        assert np.array_equal(log.samples, reference)
    csv = tmp_path / "jackal.csv"
    csv.write_text("time,x,y\n" + "".join(f"{t!r},{x!r},{y!r}\n" for t, x, y in reference.tolist()))
    assert np.array_equal(read_log(csv).samples, reference)
    for name, task in HELD_OUT.items():
        mission = tmp_path / f"{name}.yaml"
        mission.write_text(
            "version: 1\nworkspace: {boundary: {rect: [-20, -20, 20, 20]}}\n"
            + REGIONS
            + "robot: {start: [0, 0]}\n"
            + task
        )
        outcomes = set()
        for path in [*paths, csv]:
            code, out, err = run("verify", str(path), "--mission", str(mission), "--json")
            assert code in (0, 1), err
            outcomes.add((code, out))
        assert len(outcomes) == 1, name


def test_log_reader_imports_nothing_from_the_planner(tmp_path: Path) -> None:
    import subprocess
    import sys

    csv = tmp_path / "log.csv"
    csv.write_text("t,x,y\n0,1,2\n")
    bag = write_bag(tmp_path / "b", "mcap", {"/odom": (POSE_TYPES[0], ROWS)})
    script = (
        "import sys\n"
        "from pathlib import Path\n"
        "from tlmpc.importers.logs import read_log\n"
        f"read_log(Path({str(csv)!r})); read_log(Path({str(bag)!r}))\n"
        "bad = [m for m in sys.modules if m.startswith(('tlmpc.automata', 'tlmpc.planning', "
        "'tlmpc.control', 'tlmpc.simulate', 'tlmpc.abstraction', 'tlmpc.pipeline', 'scipy'))]\n"
        "print(bad)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert done.stdout.strip() == "[]"
