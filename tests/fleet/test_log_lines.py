"""One way to read a log's lines for every reader (whole, streamed, live): split only at
``\\n``, ``\\r\\n`` and ``\\r``, UTF-8 with a byte-order mark skipped, the same numbers and
the same refusals whichever blocks the bytes come in."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from fleet_cli import run_cli
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.base.errors import UsageError
from tlmpc.importers.logs import MAX_LINE_CHARS, LogLines, iter_csv_chunks, split_lines

ROOT = Path(__file__).resolve().parents[2]
MISSION = str(ROOT / "specs" / "reach-avoid.yaml")


def editor_lines(text: str) -> list[str]:
    """The oracle: an editor's lines, by a regular expression (the last line break ends the
    last line instead of starting an empty one)."""
    parts = re.split(r"\r\n|\r|\n", text)
    return parts[:-1] if parts[-1] == "" else parts


def read_in_blocks(data: bytes, cuts: list[int]) -> list[str]:
    reader = LogLines("log.csv")
    lines: list[str] = []
    previous = 0
    for cut in [*sorted(cuts), len(data)]:
        lines += reader.feed(data[previous:cut])
        previous = cut
    return lines + reader.finish()


TEXT = st.text(alphabet=st.sampled_from("ab1,\n\r\f\x1e\x1c\x85\u2028\u00e9 #"), max_size=40)


@given(text=TEXT, cuts=st.lists(st.integers(min_value=0, max_value=120), max_size=6))
def test_lines_are_an_editors_in_any_blocks(text: str, cuts: list[int]) -> None:
    data = text.encode("utf-8")
    assert split_lines(text) == editor_lines(text)
    assert read_in_blocks(data, [min(c, len(data)) for c in cuts]) == editor_lines(text)
    # a byte-order mark at the start is no character of the first line
    assert read_in_blocks(b"\xef\xbb\xbf" + data, cuts) == editor_lines(text)


def test_a_line_that_is_not_utf8_is_refused_at_its_line_and_column() -> None:
    data = b"t,x,y\n0,1,1\n# caf" + b"\xe9 au lait\n1,2,2\n"
    for cuts in ([], [3], [15, 16, 17], list(range(len(data)))):
        with pytest.raises(UsageError) as raised:
            read_in_blocks(data, cuts)
        found = raised.value.diagnostics[0]
        assert (found.code, found.line, found.col) == ("M050", 3, 6)
        assert "at byte 17" in found.message
        assert found.hint


def test_an_endless_line_is_refused_before_it_is_held() -> None:
    reader = LogLines("zero.csv")
    for _ in range(4):
        reader.feed(b"\0" * MAX_LINE_CHARS)  # still possibly a line of 4-byte characters
    with pytest.raises(UsageError) as raised:
        reader.feed(b"\0")
    assert raised.value.diagnostics[0].code == "M053"
    long = b"t,x,y\n" + b"1" * (MAX_LINE_CHARS + 1) + b"\n"
    with pytest.raises(UsageError) as raised:
        read_in_blocks(long, [])
    assert (raised.value.diagnostics[0].code, raised.value.diagnostics[0].line) == ("M053", 2)


@pytest.mark.parametrize(
    "body",
    [
        b"t,x,y\n0,1,1\x0c1,7,7\n",  # a form feed where a line break should be
        b"t,x,y\n0,1,1\n1,7\x1e,7\n",  # a record separator inside a row
        b"t,x,y\n0,1,1\n1,7\xe2\x80\xa87\n",  # U+2028 inside a row
        b"t,x,y\r0,1,1\r\n20,8.5,2\r",  # old Mac and Windows line ends mixed
    ],
)
def test_verify_batch_and_monitor_read_a_file_alike(tmp_path: Path, body: bytes) -> None:
    log = tmp_path / "log.csv"
    log.write_bytes(body)
    single = run_cli("verify", str(log), "--mission", MISSION, "--json")
    batch = run_cli("verify", str(log), "--mission", MISSION, "--no-cache", "--json")
    live = run_cli("monitor", "--mission", MISSION, str(log))
    piped = run_cli("monitor", "--mission", MISSION, stdin=body)
    assert single[0] == batch[0] == live[0] == piped[0]
    if single[0] == 2:  # the same diagnostic, at the same line and column
        first = re.search(r"log\.csv:[0-9:]+: error\[\w+\]", single[2])
        assert first is not None
        assert first.group(0) in batch[1] + batch[2]
        assert first.group(0) in live[2]


def test_streamed_chunks_number_lines_as_the_whole_reader(tmp_path: Path) -> None:
    log = tmp_path / "log.csv"
    log.write_bytes(b"\xef\xbb\xbft,x,y\r\n# a\x0ccomment\r\n0,1,1\r2,3,4\n\n5,6,7")
    for block in (1, 2, 3, 7, 64):
        chunks = list(iter_csv_chunks(log, block_bytes=block))
        assert [n for c in chunks for n in c.lines] == [3, 4, 6]
        assert [row for c in chunks for row in c.samples.tolist()] == [
            [0, 1, 1],
            [2, 3, 4],
            [5, 6, 7],
        ]
