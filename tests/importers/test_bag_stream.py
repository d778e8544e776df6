"""Bags read as a stream: the same poses as the whole reader, in constant memory.

The oracle of the poses is the list the test wrote (sorted by stamp, as the whole reader
sorts); the oracle of "constant memory" is tracemalloc's peak for two bags of different
lengths read chunk by chunk; the oracle of the streamed verdict is the whole log's verdict.
"""

from __future__ import annotations

import gc
import itertools
import json
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from robot_data import write_bag

from tlmpc.cli import main
from tlmpc.importers import logs
from tlmpc.importers.logs import BagOutOfOrder, iter_bag_chunks, read_bag

ROOT = Path(__file__).resolve().parents[2]
PATROL = str(ROOT / "specs" / "patrol.yaml")


def _rows(n: int, start: int = 1_000_000_000) -> list[tuple[int, float, float]]:
    """A walk along the patrol's corridor, one pose every 10 ms."""
    return [(start + k * 10_000_000, 2.0 + 6.0 * k / max(n, 1), 5.0) for k in range(n)]


@settings(max_examples=12, deadline=None)
@given(
    n=st.integers(0, 60),
    chunk=st.integers(1, 25),
    kind=st.sampled_from(["mcap", "ros1", "sqlite3"]),
    swaps=st.lists(st.integers(0, 59), max_size=3),
)
def test_the_stream_is_the_whole_reader_in_chunks(
    tmp_path_factory: pytest.TempPathFactory, n: int, chunk: int, kind: str, swaps: list[int]
) -> None:
    rows = _rows(n)
    stamps = [t for t, _, _ in rows]
    for k in swaps:  # stamps out of order where two neighbours trade theirs
        if k + 1 < n:
            stamps[k], stamps[k + 1] = stamps[k + 1], stamps[k]
    rows = [(t, x, y) for t, (_, x, y) in zip(stamps, rows, strict=True)]
    folder = tmp_path_factory.mktemp("bag")
    name = {"mcap": "log.mcap", "ros1": "log.bag", "sqlite3": "log"}[kind]
    bag = write_bag(
        folder / name,
        kind,
        {"/odom": ("nav_msgs/msg/Odometry", rows)},
        log_times={"/odom": [1_000_000_000 + k for k in range(n)]},  # stored in this order
    )
    expected = np.array(sorted(rows, key=lambda r: r[0]), dtype=np.float64).reshape(-1, 3)
    expected[:, 0] /= 1e9
    whole = read_bag(bag)
    assert np.array_equal(whole.samples, expected)
    in_order = all(a <= b for a, b in itertools.pairwise(stamps))
    if not in_order:
        with pytest.raises(BagOutOfOrder):
            list(iter_bag_chunks(bag, chunk=chunk))
        return
    chunks = list(iter_bag_chunks(bag, chunk=chunk))
    assert all(1 <= len(c) <= chunk for c in chunks)
    assert len(chunks) == -(-n // chunk)
    streamed = np.vstack(chunks) if chunks else np.zeros((0, 3))
    assert np.array_equal(streamed, expected)


@pytest.mark.parametrize("chunk", [1, 2, 3, 50])
def test_a_streams_stamps_a_nanosecond_apart_stay_apart(tmp_path: Path, chunk: int) -> None:
    # at a real epoch a float second's step is 238 ns: ns / 1e9 would make these one time,
    # and a chunk's first stamp must stay after the chunk before's last
    epoch = 1_700_000_000 * 1_000_000_000
    rows = [(epoch + k, 2.0 + 0.01 * k, 5.0) for k in range(7)]
    bag = write_bag(tmp_path / "log.mcap", "mcap", {"/odom": ("nav_msgs/msg/Odometry", rows)})
    streamed = np.vstack(list(iter_bag_chunks(bag, chunk=chunk)))
    assert np.all(np.diff(streamed[:, 0]) > 0)
    assert np.array_equal(streamed, read_bag(bag).samples)


def _peak(bag: Path) -> int:
    gc.collect()  # garbage a neighbouring test left would count in the peak
    tracemalloc.start()
    try:
        count = sum(len(c) for c in iter_bag_chunks(bag, chunk=500))
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
        assert count > 0


@pytest.mark.slow
def test_streaming_memory_does_not_grow_with_the_messages(tmp_path: Path) -> None:
    short = write_bag(
        tmp_path / "short.mcap", "mcap", {"/odom": ("nav_msgs/msg/Odometry", _rows(4_000))}
    )
    long = write_bag(
        tmp_path / "long.mcap", "mcap", {"/odom": ("nav_msgs/msg/Odometry", _rows(16_000))}
    )
    _peak(short)  # the first read loads the reader's modules and types
    # the smaller of two reads: a cache a first read fills is not the stream's memory
    small = min(_peak(short), _peak(short))
    large = min(_peak(long), _peak(long))
    # four times the messages: the whole reader's arrays alone would add 12,000 * 24 bytes;
    # a stream's peak stays within a chunk's worth of the short bag's
    assert large - small < 100_000, (small, large)


@pytest.mark.parametrize("order", ["in order", "out of order"])
def test_a_streamed_bag_gets_the_whole_logs_verdict(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], order: str
) -> None:
    rows = _rows(300)
    if order == "out of order":  # stored in this order, two stamps traded
        rows[100], rows[101] = (rows[101][0], *rows[100][1:]), (rows[100][0], *rows[101][1:])
    bag = write_bag(
        tmp_path / "log.mcap",
        "mcap",
        {"/odom": ("nav_msgs/msg/Odometry", rows)},
        log_times={"/odom": [1_000_000_000 + k for k in range(300)]},
    )
    whole = main(["verify", str(bag), "--mission", PATROL, "--json"])
    whole_out = capsys.readouterr().out
    monkeypatch.setattr(logs, "BAG_STREAM_FROM", 10)
    streamed = main(["verify", str(bag), "--mission", PATROL, "--json"])
    captured = capsys.readouterr()
    assert "streamed (300 samples" in captured.err
    assert streamed == whole
    a, b = json.loads(whole_out)["result"], json.loads(captured.out)["result"]
    assert (a["verdict"], a["satisfied"]) == (b["verdict"], b["satisfied"])
    assert a["violations"] == b["violations"]
    assert a["stats"]["samples"] == b["stats"]["samples"] == 300
