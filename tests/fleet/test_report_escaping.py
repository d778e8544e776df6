"""The fleet report shows a log's path as every tlmpc output shows names: a direction control
in a file name is a visible escape (it would reorder the rest of the cell), bytes that are not
UTF-8 are ``\\xNN``."""

from __future__ import annotations

import io
import os
from pathlib import Path

import pytest

from tlmpc.base.errors import is_unsafe_char
from tlmpc.cli import main
from tlmpc.fleet.output import visible

ROOT = Path(__file__).resolve().parents[2]


def test_a_log_name_with_a_direction_control_is_shown_escaped(tmp_path: Path) -> None:
    day = tmp_path / "logs" / "r5" / "2026-11-03"
    day.mkdir(parents=True)
    samples = "t,x,y\n" + "".join(f"{i},{1.5 + 0.1 * i},1.5\n" for i in range(5))
    (day / "\u202ecod.exe.csv").write_text(samples)
    (day / "plain.csv").write_text(samples)
    bad_bytes = os.fsencode(day) + b"/caf\xe9.csv"
    with open(bad_bytes, "w") as handle:
        handle.write(samples)
    report = tmp_path / "rep.html"
    err = io.StringIO()
    code = main(
        [
            "verify",
            str(tmp_path / "logs"),
            "--mission",
            str(ROOT / "specs" / "example1.yaml"),
            "--report",
            str(report),
            "--no-cache",
        ],
        out=io.StringIO(),
        err=err,
    )
    assert code in (0, 1, 4), err.getvalue()
    page = report.read_text(encoding="utf-8")
    assert "\\u202ecod.exe.csv" in page
    assert "caf\\xe9.csv" in page
    assert not any(is_unsafe_char(ch) for ch in page if ch not in "\n\t")


@pytest.mark.parametrize(
    ("text", "shown"),
    [
        ("caf\udce9.csv", "caf\\xe9.csv"),
        ("a\ud800b", "a\\ud800b"),
        ("\udcff\udc80\udfff", "\\xff\\x80\\udfff"),
        ("robot-1/\u00e9t\u00e9.csv", "robot-1/\u00e9t\u00e9.csv"),
    ],
)
def test_any_lone_surrogate_is_shown_never_raised(text: str, shown: str) -> None:
    # a file name's undecodable bytes and an escaped surrogate read from JSON alike
    assert visible(text) == shown
