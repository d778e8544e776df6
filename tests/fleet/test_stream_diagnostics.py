"""A streamed log's sample problems are a whole log's, however it is cut into chunks: each
problem once, the same kinds left out (a sample that is not finite leaves out the others, one
too large the order checks), at most three of each kind, in the log's order.

The oracle is the rule written in docs/verify.md and tlmpc/verify/samples.py, applied to the
rows as generated: it knows which rows were spoiled and how."""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest

from tlmpc.base.errors import UsageError
from tlmpc.fleet.stream import verify_log
from tlmpc.verify.trace_input import mission_document

MISSION = """\
version: 1
name: m
workspace:
  boundary: {rect: [0, 0, 10, 10]}
regions:
  a: {rect: [2, 2, 4, 4]}
robot: {start: [1, 1], max_speed: 3.0}
ltl: "G !a"
"""


def _expected(rows: list[tuple[float, float, float]]) -> list[tuple[str, int]]:
    """(code, line) of each problem a whole log reports; line 1 is the header."""
    line = {index: index + 2 for index in range(len(rows))}
    bad = [i for i, row in enumerate(rows) if not all(math.isfinite(v) for v in row)]
    if bad:
        return [("V003", line[i]) for i in bad[:3]]
    far = [i for i, row in enumerate(rows) if any(abs(v) > 1e12 for v in row)]
    if far:
        return [("V024", line[i]) for i in far[:3]]
    back = [i for i in range(1, len(rows)) if rows[i][0] < rows[i - 1][0]]
    same = [i for i in range(1, len(rows)) if rows[i][0] == rows[i - 1][0]]
    return [("V005", line[i]) for i in back[:3]] + [("V020", line[i]) for i in same[:3]]


def _rows(rng: random.Random) -> list[tuple[float, float, float]]:
    rows = []
    t = 0.0
    for _ in range(rng.randint(2, 14)):
        t += rng.choice([1.0, 1.0, 1.0, 0.0, -2.0])
        x, y = rng.uniform(0, 10), rng.uniform(0, 10)
        spoil = rng.random()
        if spoil < 0.08:
            x = math.nan
        elif spoil < 0.12:
            y = math.inf
        elif spoil < 0.16:
            x = 5e12
        rows.append((t, x, y))
    return rows


def _streamed(path: Path, document: dict[str, object], block: int) -> list[tuple[str, int]]:
    with pytest.raises(UsageError) as caught:
        verify_log(path, document, block_bytes=block)
    return [(d.code, d.line or 0) for d in caught.value.diagnostics]


def test_a_sample_spoiled_at_the_end_of_a_chunk_is_reported_once(tmp_path: Path) -> None:
    (tmp_path / "m.yaml").write_text(MISSION)
    document = mission_document(tmp_path / "log.csv", tmp_path / "m.yaml")
    log = tmp_path / "log.csv"
    # the last line has no line break: it is a chunk of its own, joined to the spoiled one
    log.write_text("t,x,y\n0,1,1\n1,nan,1\n2,2,2")
    assert _streamed(log, document, 1 << 22) == [("V003", 3)]
    log.write_text("t,x,y\n0,1,1\n1,nan,1\n2,2,2\n3,inf,3\n4,nan,4\n5,5,5")
    assert _streamed(log, document, 16) == [("V003", 3), ("V003", 5), ("V003", 6)]


def test_chunked_logs_report_what_a_whole_log_reports(tmp_path: Path) -> None:
    (tmp_path / "m.yaml").write_text(MISSION)
    log = tmp_path / "log.csv"
    document = mission_document(log, tmp_path / "m.yaml")
    rng = random.Random(7)
    checked = 0
    for _ in range(150):
        rows = _rows(rng)
        expected = _expected(rows)
        if not expected:
            continue
        log.write_text("t,x,y\n" + "".join(f"{t!r},{x!r},{y!r}\n" for t, x, y in rows))
        for block in (8, 24, 64, 1 << 22):  # a chunk per line or two ... the whole log at once
            assert _streamed(log, document, block) == expected, (rows, block)
        checked += 1
    assert checked > 60
