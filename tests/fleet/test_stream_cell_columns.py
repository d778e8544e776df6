"""A streamed or batched CSV log's sample problems (V003, V005, V020, V024, M053) are placed
at the line and the column of the cell at fault, and its samples numbered, as a single log's
are: checked on random logs (separators, quoting, column orders, line ends) against my own
split of the line with the csv module."""

from __future__ import annotations

import csv
import io
import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.fleet.stream import verify_log
from tlmpc.verify import trace_input
from tlmpc.verify.trace_input import mission_document

MISSION = """\
version: 1
workspace: {boundary: {rect: [0, 0, 10, 10]}}
regions:
  a: {rect: [2, 2, 4, 4]}
  b: {rect: [6, 6, 8, 8]}
robot: {start: [1, 1], max_speed: 100}
task: [visit a, avoid b]
"""

#: the wrong value written in the bad cell, for each kind of problem (None: derived from
#: the row before)
KINDS = {"V003": ["nan", "-inf", "1e400"], "V024": ["-3e15"], "M053": ["oops", "1..5"]}


#: header lines, and which of t, x, y (0, 1, 2) each column after a "seq" column holds
LAYOUTS = [
    ([], [0, 1, 2]),
    (["t", "x", "y"], [0, 1, 2]),
    (["seq", "y", "t", "x"], [2, 0, 1]),
    (["x", "time", "y"], [1, 0, 2]),
]


@dataclass(frozen=True)
class Planted:
    """A CSV log's text with one bad cell: its line (1-based), its cell (0 t, 1 x, 2 y)."""

    text: str
    lines: list[str]
    separator: str
    code: str
    line: int
    column_index: int  # the bad cell's index among the line's cells
    sample: int  # the bad sample's number in the log (from 0)


@st.composite
def planted_logs(draw: st.DrawFn) -> Planted:
    separator = draw(st.sampled_from([",", ";", "\t", " ", "  "]))
    quote = draw(st.sampled_from(["", '"']))
    padding = draw(st.sampled_from(["", " "])) if separator in ",;\t" else ""
    end = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    count = draw(st.integers(3, 40))
    rows = [
        [f"{0.5 * i + 1!r}", f"{1 + (i % 7)!r}", f"{2 + (i % 5) * 0.5!r}"] for i in range(count)
    ]
    bad = draw(st.integers(1, count - 1))
    code = draw(st.sampled_from(["V003", "V024", "V005", "V020", "M053"]))
    cell = draw(st.integers(0, 2)) if code in KINDS else 0
    if code in KINDS:
        rows[bad][cell] = draw(st.sampled_from(KINDS[code]))
    elif code == "V005":
        rows[bad][0] = repr(0.5 * bad + 1 - 0.75)
    else:
        rows[bad][0] = rows[bad - 1][0]
    # t, x, y as they come, or after a sequence number and in another order, named or not
    header, order = draw(st.sampled_from(LAYOUTS))
    extra = header[:1] == ["seq"]
    written = [
        ([str(n)] if extra else []) + [f"{quote}{row[i]}{quote}" for i in order]
        for n, row in enumerate(rows)
    ]
    lines = ([separator.join(header)] if header else []) + [
        (separator + padding).join(cells) for cells in written
    ]
    comment = draw(st.booleans())
    if comment:
        lines.insert(0, "# a robot log")
    line = bad + 1 + bool(header) + comment
    return Planted(
        text=end.join(lines) + end,
        lines=lines,
        separator=separator,
        code=code,
        line=line,
        column_index=order.index(cell) + extra,
        sample=bad,
    )


def split(line: str, separator: str) -> list[str]:
    """My own cut of a log line: the csv module, blanks collapsed for blank separators."""
    delimiter = " " if separator.strip(" ") == "" else separator
    return next(csv.reader([line], delimiter=delimiter, skipinitialspace=True))


def assert_at_bad_cell(
    planted: Planted, code: str, line: int, col: int | None, message: str
) -> None:
    assert code == planted.code
    if code != "M053":  # numbered as the whole log numbers its samples, wherever its chunks end
        assert f"sample {planted.sample} (line {planted.line})" in message
    assert line == planted.line
    assert col is not None, f"{code} at line {line} has no column"
    text = planted.lines[line - 1]
    cells = split(text, planted.separator)
    wanted = cells[planted.column_index].strip()
    # the column starts the bad cell: the text before it holds every cell before it, and
    # the bad cell's value starts there
    before = split(text[: col - 1] + "|", planted.separator)
    assert len(before) == planted.column_index + 1, (text, col)
    assert before[-1].strip().strip('"') == "|", (text, col)
    assert text[col - 1 :].startswith(wanted), (text, col, wanted)


def problem_of(message: str) -> tuple[str, int, int | None, str]:
    """The code, line, column and message of the first problem in a batch record's message."""
    found = re.search(r":(\d+)(?::(\d+))?: error\[(\w+)\]", message)
    assert found is not None, message
    return found[3], int(found[1]), int(found[2]) if found[2] else None, message


def run(*argv: str) -> dict[str, Any]:
    out = io.StringIO()
    main([*argv, "--json"], out=out, err=io.StringIO())
    result: dict[str, Any] = json.loads(out.getvalue())
    return result


SETTINGS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@SETTINGS
@given(planted=planted_logs())
def test_a_batch_places_the_bad_cell(tmp_path: Path, planted: Planted) -> None:
    """Two logs, one worker: the broken one's record names the bad cell's column."""
    (tmp_path / "mission.yaml").write_text(MISSION)
    (tmp_path / "bad.csv").write_bytes(planted.text.encode())
    (tmp_path / "good.csv").write_text("t,x,y\n0,1,1\n1,3,3\n")
    result = run(
        "verify",
        str(tmp_path / "bad.csv"),
        str(tmp_path / "good.csv"),
        "--mission",
        str(tmp_path / "mission.yaml"),
        "--jobs",
        "1",
        "--no-cache",
    )
    (record,) = [r for r in result["result"]["logs"] if r["log"].endswith("bad.csv")]
    assert_at_bad_cell(planted, *problem_of(record["error"]["message"]))


@SETTINGS
@given(planted=planted_logs())
def test_a_long_log_streamed_places_the_bad_cell(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, planted: Planted
) -> None:
    """A single log past the whole reader's row limit (lowered here) is streamed, and its
    diagnostic carries the bad cell's column."""
    monkeypatch.setattr(trace_input, "MAX_CSV_ROWS", 2)
    (tmp_path / "mission.yaml").write_text(MISSION)
    (tmp_path / "long.csv").write_bytes(planted.text.encode())
    result = run("verify", str(tmp_path / "long.csv"), "--mission", str(tmp_path / "mission.yaml"))
    (problem, *_) = result["diagnostics"]
    assert_at_bad_cell(
        planted, problem["code"], problem["line"], problem.get("col"), problem["message"]
    )


@SETTINGS
@given(planted=planted_logs(), block=st.integers(8, 64))
def test_small_blocks_place_the_bad_cell(tmp_path: Path, planted: Planted, block: int) -> None:
    """Blocks of a few bytes: the bad sample and the one before it may lie in two chunks."""
    mission = tmp_path / "mission.yaml"
    mission.write_text(MISSION)
    path = tmp_path / "log.csv"
    path.write_bytes(planted.text.encode())
    with pytest.raises(UsageError) as caught:
        verify_log(path, mission_document(path, mission), block_bytes=block)
    problem = caught.value.diagnostics[0]
    assert_at_bad_cell(planted, problem.code, problem.line or 0, problem.col, problem.message)


def test_a_clean_log_is_read_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Placing cells reads the log a second time only when a problem is found."""
    from tlmpc.io import inputs

    opened: list[Path] = []
    real = inputs.open_regular

    def counting(path: Path, **options: Any) -> Any:
        opened.append(path)
        return real(path, **options)

    mission = tmp_path / "mission.yaml"
    mission.write_text(MISSION)
    path = tmp_path / "log.csv"
    path.write_text("t,x,y\n" + "".join(f"{i},{1 + i % 3},1\n" for i in range(200)))
    document = mission_document(path, mission)
    monkeypatch.setattr(inputs, "open_regular", counting)
    verify_log(path, document, block_bytes=64)
    assert opened == [path]
