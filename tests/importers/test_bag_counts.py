"""A damaged bag that a reader opens and reads without an error, but with messages missing, is
refused (M065, or M060 for a sqlite3 file that fails SQLite's own check), never read as a
shorter log.

The oracles are independent of tlmpc and rosbags: the ``mcap`` library reads every message
record of the damaged MCAP file (the file holds them all, and its summary says how many), and
the standard library's ``sqlite3`` counts the rows a damaged database still answers with and
runs its ``quick_check``.
"""

from __future__ import annotations

import contextlib
import re
import sqlite3
import struct
from pathlib import Path

import numpy as np
import pytest
import yaml
from robot_data import write_bag

from tlmpc.base.errors import UsageError
from tlmpc.importers.logs import iter_bag_chunks, read_log

TOPIC = "/odom"
ODOMETRY = "nav_msgs/msg/Odometry"


def _rows(n: int) -> list[tuple[int, float, float]]:
    return [((k + 1) * 1_000_000_000, float(k), 0.0) for k in range(n)]


def _refusal(path: Path) -> tuple[str, str]:
    """The code and message both readers (whole and streamed) refuse ``path`` with."""
    found = []
    for read in (lambda: read_log(path), lambda: list(iter_bag_chunks(path, chunk=2))):
        with pytest.raises(UsageError) as caught:
            read()
        found.append((caught.value.diagnostics[0].code, caught.value.diagnostics[0].message))
    assert found[0] == found[1]
    return found[0]


def _mcap_bag(tmp_path: Path, n: int = 5) -> Path:
    """A ROS 2 MCAP bag directory (uncompressed chunks, no CRC) with ``n`` poses."""
    bag = write_bag(tmp_path / "bag", "mcap", {TOPIC: (ODOMETRY, _rows(n))})
    return next(bag.glob("*.mcap"))


def _mcap_records(file: Path) -> tuple[int, int]:
    """The ``mcap`` library's count of the file's message records, and its summary's count."""
    from mcap.reader import make_reader

    with open(file, "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None
        assert summary.statistics is not None
        declared = summary.statistics.message_count
    with open(file, "rb") as stream:
        # a plain walk of the records, which skips nothing
        from mcap.stream_reader import StreamReader

        records = sum(type(r).__name__ == "Message" for r in StreamReader(stream).records)
    return records, declared


def _message_at(data: bytes | bytearray, log_time: int) -> int:
    """The offset of the message record (opcode 0x05) whose log time is ``log_time``."""
    at = data.index(struct.pack("<QQ", log_time, log_time)) - 15  # after channel and sequence
    assert data[at] == 0x05
    return at


@pytest.mark.parametrize("whole_dir", [True, False])
def test_an_mcap_message_with_a_garbled_log_time_is_refused_not_dropped(
    tmp_path: Path, whole_dir: bool
) -> None:
    file = _mcap_bag(tmp_path)
    data = bytearray(file.read_bytes())
    data[_message_at(data, 3_000_000_000) + 1 + 8 + 2 + 4 + 7] ^= 0x20  # log time's top byte
    file.write_bytes(bytes(data))
    assert _mcap_records(file) == (5, 5)  # the record is there, and counted by the summary

    code, message = _refusal(file.parent if whole_dir else file)
    assert code == "M065"
    assert "declares 5 messages on /odom" in message
    assert "4 could be read" in message
    assert "outside the chunk's 1,000,000,000-5,000,000,000 ns" in message
    assert ("metadata.yaml" in message) == whole_dir


def test_an_mcap_message_on_a_garbled_channel_is_refused(tmp_path: Path) -> None:
    file = _mcap_bag(tmp_path)
    data = bytearray(file.read_bytes())
    data[_message_at(data, 2_000_000_000) + 1 + 8 + 1] ^= 0x01  # channel 1 -> 257
    file.write_bytes(bytes(data))
    assert _mcap_records(file) == (5, 5)

    code, message = _refusal(file)
    assert code == "M065"
    assert "on channel 257, which the file does not declare" in message


@pytest.mark.parametrize("kind", ["sqlite3", "mcap"])
def test_metadata_declaring_more_messages_than_the_bag_holds_is_refused(
    tmp_path: Path, kind: str
) -> None:
    bag = write_bag(tmp_path / "bag", kind, {TOPIC: (ODOMETRY, _rows(5))})
    metadata = bag / "metadata.yaml"
    information = yaml.safe_load(metadata.read_text())
    (topic,) = information["rosbag2_bagfile_information"]["topics_with_message_count"]
    assert topic["message_count"] == 5
    topic["message_count"] = 7
    metadata.write_text(yaml.safe_dump(information))

    code, message = _refusal(bag)
    assert code == "M065"
    assert "declares 7 messages on /odom (metadata.yaml), but 5 could be read" in message


def _drop_a_row_silently(database: Path) -> int:
    """Lower the cell count of the first leaf page (of a table or an index) whose last entry
    SQLite then loses without an error; how many rows the messages table still answers with."""
    data = database.read_bytes()
    page = int.from_bytes(data[16:18], "big")
    rows = _sqlite_rows(database)
    for start in range(page, len(data), page):
        if data[start] not in (0x0A, 0x0D):  # an index's or a table's leaf page
            continue
        cells = int.from_bytes(data[start + 3 : start + 5], "big")
        damaged = bytearray(data)
        damaged[start + 3 : start + 5] = (cells - 1).to_bytes(2, "big")
        database.write_bytes(bytes(damaged))
        with contextlib.suppress(sqlite3.DatabaseError):
            if _sqlite_rows(database) == rows - 1:
                return rows - 1
    raise AssertionError("no page loses a row silently")


def _sqlite_rows(database: Path) -> int:
    """How many rows of the messages table a reader's query (every column, by time) gets."""
    with contextlib.closing(sqlite3.connect(f"{database.as_uri()}?immutable=1", uri=True)) as db:
        return len(db.execute("SELECT * FROM messages ORDER BY timestamp").fetchall())


def _quick_check(database: Path) -> list[str]:
    with contextlib.closing(sqlite3.connect(f"{database.as_uri()}?immutable=1", uri=True)) as db:
        return [str(row[0]) for row in db.execute("PRAGMA quick_check")]


def test_a_damaged_sqlite3_bag_is_refused_by_its_quick_check(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / "bag", "sqlite3", {TOPIC: (ODOMETRY, _rows(200))})
    database = next(bag.glob("*.db3")).resolve()
    assert _drop_a_row_silently(database) == 199
    assert _quick_check(database) != ["ok"]

    for path in (bag, database):
        code, message = _refusal(path)
        assert code == "M060"
        assert "SQLite's quick_check finds" in message


def test_a_ros1_bag_whose_chunk_infos_count_more_messages_is_refused(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / "log.bag", "ros1", {TOPIC: (ODOMETRY, _rows(5))})
    data = bytearray(bag.read_bytes())
    pairs = _chunk_info_data(bytes(data))  # (connection id, count) pairs
    connection, count = struct.unpack_from("<II", data, pairs)
    assert count == 5
    struct.pack_into("<II", data, pairs, connection, 6)
    bag.write_bytes(bytes(data))

    code, message = _refusal(bag)
    assert code == "M065"
    assert re.search(r"declares 6 messages on /odom \(its chunk infos\), but 5 could", message)


def _chunk_info_data(data: bytes) -> int:
    """Where the data of a ROS 1 bag's chunk info record (op 0x06) begins: records are a
    header (its length, then length-prefixed ``name=value`` fields) and data (its length, then
    bytes), after the 13-byte magic."""
    at = len(b"#ROSBAG V2.0\n")
    while at < len(data):
        header_length = int.from_bytes(data[at : at + 4], "little")
        header = data[at + 4 : at + 4 + header_length]
        data_at = at + 4 + header_length + 4
        if b"op=\x06" in header:
            return data_at
        at = data_at + int.from_bytes(data[data_at - 4 : data_at], "little")
    raise AssertionError("no chunk info record")


@pytest.mark.parametrize("kind", ["ros1", "sqlite3", "mcap"])
def test_an_undamaged_bag_reads_whole(tmp_path: Path, kind: str) -> None:
    path = write_bag(
        tmp_path / ("log.bag" if kind == "ros1" else "bag"),
        kind,
        {
            TOPIC: (ODOMETRY, _rows(7)),
            "/chatter": ("std_msgs/msg/String", _rows(3)),
        },
    )
    assert len(read_log(path).samples) == 7
    assert sum(len(chunk) for chunk in iter_bag_chunks(path, chunk=3)) == 7


def test_a_tf_topic_missing_messages_is_refused_with_frame(tmp_path: Path) -> None:
    from test_importers_frames import scenario, write_tf_bag

    poses, tf, static = scenario(np.random.default_rng(7), tilt=0.0)
    bag = write_tf_bag(tmp_path / "bag", "mcap", poses, "odom", tf, static)
    metadata = bag / "metadata.yaml"
    information = yaml.safe_load(metadata.read_text())
    topics = information["rosbag2_bagfile_information"]["topics_with_message_count"]
    (transforms,) = [t for t in topics if t["topic_metadata"]["name"] == "/tf"]
    declared = transforms["message_count"] + 1
    transforms["message_count"] = declared
    metadata.write_text(yaml.safe_dump(information))

    assert len(read_log(bag).samples) == len(poses)  # the poses alone add up
    with pytest.raises(UsageError) as caught:
        read_log(bag, frame="map")
    assert caught.value.diagnostics[0].code == "M065"
    assert f"declares {declared} messages on /tf (metadata.yaml)" in (
        caught.value.diagnostics[0].message
    )
