"""The "wrote FILE" line of a command is one line, whatever the file's name holds.

A log's name (a file a robot wrote) becomes the name of its page in `tlmpc view --log`, and
any `-o` name is printed back: a newline in it must not start a second line that reads like
a diagnostic (docs/cli.md: no name can "forge a diagnostic line").
"""

from __future__ import annotations

import io
import shutil
from pathlib import Path

import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
MISSION = ROOT / "specs" / "example1.yaml"
FORGED = "\nmission.yaml:3:1: error[L010]: unknown region p9"


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("names") / "out"
    code, _, err = run_cli("compile", str(MISSION), "-o", str(out), "-q")
    assert code == 0, err
    return out


def _lines(text: str) -> list[str]:
    return text.splitlines()


@pytest.mark.parametrize(
    "command",
    [
        ("export-plan", "{out}", "-o", "{target}.yaml"),
        ("export", "{out}", "--format", "dot", "-o", "{target}.dot"),
        ("plot", "{copy}"),
    ],
)
def test_a_written_files_name_stays_on_its_line(
    compiled: Path, tmp_path: Path, command: tuple[str, ...]
) -> None:
    copy = tmp_path / f"copy{FORGED}"
    shutil.copytree(compiled, copy)
    values = {"out": str(compiled), "target": str(tmp_path / f"plan{FORGED}"), "copy": str(copy)}
    code, _, err = run_cli(*(part.format(**values) for part in command))
    assert code == 0, err
    (line,) = _lines(err)
    assert line.startswith("wrote ")
    assert "\\x0amission.yaml:3:1: error[L010]" in line


def test_a_logs_page_is_named_on_one_line(compiled: Path, tmp_path: Path) -> None:
    log = tmp_path / f"run{FORGED}.json"
    shutil.copy(compiled / "trace.json", log)
    code, out, err = run_cli("view", "--log", str(log), "--mission", str(MISSION))
    assert code == 0, err
    assert log.with_suffix(".html").is_file()
    (line,) = _lines(out)
    assert line.startswith("wrote ")
    assert "error[L010]" in line
    assert err == ""


def test_compile_names_its_output_on_one_line(tmp_path: Path) -> None:
    code, _, err = run_cli("compile", str(MISSION), "-o", str(tmp_path / f"out{FORGED}"))
    assert code == 0, err
    assert not [line for line in _lines(err) if line.startswith("mission.yaml:")]
