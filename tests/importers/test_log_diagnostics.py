"""A robot log's problems are placed where they are: a CSV's line and the column of the cell
at fault, a too-long line's number, a map YAML's unreadable value, a bag's undecodable
message with its topic and number; each with a hint."""

from __future__ import annotations

import io
import json
import math
import random
import re
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main

MISSION = """\
version: 1
workspace: {boundary: {rect: [0, 0, 10, 10]}}
regions:
  a: {rect: [2, 2, 4, 4]}
  b: {rect: [6, 6, 8, 8]}
robot: {start: [1, 1], max_speed: 100}
task: [visit a, avoid b]
"""


def verify(*argv: str) -> tuple[int, dict[str, Any]]:
    out = io.StringIO()
    code = main(["verify", *argv, "--json"], out=out, err=io.StringIO())
    return code, json.loads(out.getvalue())


@pytest.fixture
def mission(tmp_path: Path) -> Path:
    path = tmp_path / "mission.yaml"
    path.write_text(MISSION)
    return path


def cell_at(line: str, col: int) -> str:
    """The cell that starts at ``col`` (1-based), by my own cutting of the line."""
    return re.split(r"[,;\t ]", line[col - 1 :])[0].strip("\"'")


def test_sample_problems_point_at_their_cell(tmp_path: Path, mission: Path) -> None:
    """Random logs with one bad sample each (not finite, beyond 1e12, backwards, repeated):
    the diagnostic's line and column hold the offending number, read by my own split."""
    rng = random.Random(3)
    path = tmp_path / "log.csv"
    checked = 0
    for _ in range(60):
        separator = rng.choice([",", ";", "\t", " ", "  "])
        quote = rng.choice(["", '"'])
        rows = [[0.5 * i + 1, rng.uniform(0, 10), rng.uniform(0, 10)] for i in range(6)]
        cells = [[f"{quote}{v!r}{quote}" for v in row] for row in rows]
        bad = rng.randrange(1, 6)
        kind = rng.choice(["nan", "huge", "backwards", "repeat"])
        cell = rng.randrange(3) if kind in ("nan", "huge") else 0
        if kind == "nan":
            cells[bad][cell] = rng.choice(["nan", "-inf", "1e400"])
        elif kind == "huge":
            cells[bad][cell] = "-3e15"
        elif kind == "backwards":
            cells[bad][0] = repr(rows[bad - 1][0] - 0.25)
        else:
            cells[bad][0] = cells[bad - 1][0]
        # t, x, y as they come, or after a sequence number and in another order
        header = rng.choice([[], ["t", "x", "y"], ["seq", "y", "t", "x"]])
        order = [2, 0, 1] if len(header) == 4 else [0, 1, 2]
        written = [
            ([str(number)] if len(header) == 4 else []) + [row[i] for i in order]
            for number, row in enumerate(cells)
        ]
        lines = ([separator.join(header)] if header else []) + [
            " " * rng.randint(0, 2) + separator.join(row) for row in written
        ]
        path.write_text("\r\n".join(lines) + "\n")
        status, envelope = verify(str(path), "--mission", str(mission))
        assert status == 2
        (diagnostic,) = envelope["diagnostics"]
        code = {"nan": "V003", "huge": "V024", "backwards": "V005", "repeat": "V020"}[kind]
        assert diagnostic["code"] == code
        assert diagnostic["hint"]
        line = lines[diagnostic["line"] - 1]
        assert diagnostic["line"] == bad + 1 + bool(header)
        assert cell_at(line, diagnostic["col"]) == cells[bad][cell].strip('"')
        checked += 1
    assert checked == 60


@pytest.mark.parametrize(
    ("text", "code", "line", "col"),
    [
        ("t,x,y\n0,1,1\n1,2\n", "M053", 3, 4),  # a short row: where its missing cell would be
        ("t,x,y\n0,1,1\n  1;2  \n", "M053", 3, 6),
        ("t,a,b\n0,1,1\n", "M052", 1, 1),
        ("stamp,pose.x,odom.x,y\n0,1,1,1\n", "M052", 1, 7),  # the first of two x columns
        ("0,1,1,5\n", "M052", 1, 7),  # no header, a fourth column
    ],
)
def test_row_and_column_problems_are_placed(
    tmp_path: Path, mission: Path, text: str, code: str, line: int, col: int
) -> None:
    path = tmp_path / "log.csv"
    path.write_text(text)
    status, envelope = verify(str(path), "--mission", str(mission))
    assert status == 2
    (diagnostic,) = envelope["diagnostics"]
    assert (diagnostic["code"], diagnostic["line"], diagnostic["col"]) == (code, line, col)
    assert diagnostic["hint"]


@pytest.mark.parametrize("end", ["\n", "\r\n", "\r"])
def test_line_ends_count_as_the_readers_count_them(tmp_path: Path, mission: Path, end: str) -> None:
    """A log of short lines ended by a lone CR is read like the same log with LF ends (it is
    no 8-KB line), and an over-long line is refused at its number, whatever the line ends."""
    rows = ["t,x,y"] + [f"{0.1 * i!r},{3 + math.sin(i)!r},3" for i in range(1000)]
    reference = tmp_path / "lf.csv"
    reference.write_text("\n".join(rows) + "\n", newline="")
    path = tmp_path / "log.csv"
    path.write_text(end.join(rows) + end, newline="")
    assert (
        verify(str(path), "--mission", str(mission))[1]["result"]["verdict"]
        == (verify(str(reference), "--mission", str(mission))[1]["result"]["verdict"])
    )
    rows[700] = "70," + "1" * 5000 + ",3"
    path.write_text(end.join(rows) + end, newline="")
    status, envelope = verify(str(path), "--mission", str(mission))
    assert status == 2
    (diagnostic,) = envelope["diagnostics"]
    assert (diagnostic["code"], diagnostic["line"]) == ("U038", 701)


def test_an_unreadable_map_value_is_placed(tmp_path: Path) -> None:
    from PIL import Image

    Image.new("L", (10, 10), 255).save(tmp_path / "map.png")
    for text, line, col in [
        ("image: map.png\nresolution: !!float abc\norigin: [0, 0, 0]\n", 2, 13),
        ("image: map.png\nresolution: 0.1\norigin: [0, !!timestamp 2020-99-99, 0]\n", 3, 13),
    ]:
        path = tmp_path / "map.yaml"
        path.write_text(text + "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
        err = io.StringIO()
        argv = ["import-map", str(path), "-o", str(tmp_path / "m.yaml")]
        assert main(argv, out=io.StringIO(), err=err) == 2
        assert f"{path}:{line}:{col}: error[M002]: " in err.getvalue()
        assert "\n  hint: " in err.getvalue()


@pytest.mark.parametrize("kind", ["ros1", "mcap"])
def test_an_undecodable_bag_message_is_named_with_a_hint(
    tmp_path: Path, mission: Path, kind: str
) -> None:
    pytest.importorskip("rosbags")
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC if kind == "ros1" else Stores.ROS2_HUMBLE)
    if kind == "ros1":
        from rosbags.rosbag1 import Writer as Writer1

        path = tmp_path / "log.bag"
        with Writer1(path) as writer1:
            connection = writer1.add_connection(
                "/pose", "geometry_msgs/msg/PoseStamped", typestore=store
            )
            writer1.write(connection, 1_000, b"\x07" * 10)
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        path = tmp_path / "log"
        with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
            connection = writer.add_connection(
                "/pose", "geometry_msgs/msg/PoseStamped", typestore=store
            )
            writer.write(connection, 1_000, b"\x00\x01\x00\x00" + b"\x07" * 10)
    status, envelope = verify(str(path), "--mission", str(mission))
    assert status == 2
    (diagnostic,) = envelope["diagnostics"]
    assert diagnostic["code"] == "M065"
    assert "pose message 1 on /pose, log time 1000 ns" in diagnostic["message"]
    assert diagnostic["hint"]


@pytest.mark.parametrize(
    ("text", "code", "line", "cell"),
    [
        ("t;x;y\n0;1;1\n1;2;2\n0.5;3;3\n", "V005", 4, "0.5"),
        ('{"t": 0, "x": 1, "y": 1}\n{"y": 1, "x": 2, "t": 0}\n', "V020", 2, "0"),
        ('{"t": 0, "x": 1, "y": 1}\n{"t": 1, "x": 1,  "y": Infinity}\n', "V003", 2, "Infinity"),
    ],
)
def test_the_monitor_places_a_pose_at_its_cell(
    tmp_path: Path, mission: Path, text: str, code: str, line: int, cell: str
) -> None:
    path = tmp_path / "live.csv"
    path.write_text(text)
    err = io.StringIO()
    argv = ["monitor", "--mission", str(mission), str(path)]
    assert main(argv, out=io.StringIO(), err=err) == 2
    found = re.search(rf"{re.escape(str(path))}:(\d+):(\d+): error\[{code}\]", err.getvalue())
    assert found is not None, err.getvalue()
    assert int(found.group(1)) == line
    written = text.split("\n")[line - 1]
    assert written[int(found.group(2)) - 1 :].startswith(cell)


def test_the_size_check_counts_lines_as_the_readers_do(tmp_path: Path) -> None:
    """Random mixes of LF, CR LF and lone CR, and lines around the 4,096-byte limit: the rows,
    longest line and first too-long line the size check sees are my own split's."""
    from tlmpc.verify.trace_input import MAX_CSV_LINE, _csv_extent

    rng = random.Random(7)
    path = tmp_path / "log.csv"
    for _ in range(200):
        lengths = [rng.choice([0, 3, MAX_CSV_LINE, MAX_CSV_LINE + 1]) for _ in range(6)]
        ends = [rng.choice([b"\n", b"\r\n", b"\r"]) for _ in lengths]
        data = b"".join(b"7" * n + end for n, end in zip(lengths, ends, strict=True))
        if rng.random() < 0.5:
            data = data[: rng.randrange(len(data) + 1)]
        path.write_bytes(data)
        parts = re.split(rb"\r\n|\r|\n", data)
        long_lines = [i + 1 for i, part in enumerate(parts) if len(part) > MAX_CSV_LINE]
        extent = _csv_extent(path)
        assert extent.rows == len(parts) - 1
        assert extent.longest == max(map(len, parts))
        assert extent.long_line == (long_lines[0] if long_lines else None)
