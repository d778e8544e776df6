"""The CLI under hostile conditions: closed pipes, full disks, signals, control characters."""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import typing
from pathlib import Path

import pytest

from tlmpc import cli
from tlmpc.base.errors import error, printable
from tlmpc.cli import main
from tlmpc.io.artifacts import json_text

ROOT = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def tlmpc(*argv: str, **kwargs: typing.Any) -> subprocess.Popen[bytes]:
    process: subprocess.Popen[bytes] = subprocess.Popen(
        [sys.executable, "-m", "tlmpc", *argv], env=ENV, cwd=ROOT, **kwargs
    )
    return process


def test_full_stdout_is_a_u_code_not_a_traceback() -> None:
    with open("/dev/full", "w") as full:
        process = tlmpc(
            "check", "--json", "specs/example1.yaml", stdout=full, stderr=subprocess.PIPE
        )
        _, err = process.communicate()
    assert process.returncode == 2
    assert b"error[U035]" in err
    assert b"Traceback" not in err


def test_closed_pipe_exits_quietly() -> None:
    read, write = os.pipe()
    os.close(read)  # like `| head -1` that has already exited
    process = tlmpc("check", "--json", "specs/example1.yaml", stdout=write, stderr=subprocess.PIPE)
    os.close(write)
    _, err = process.communicate()
    assert process.returncode == 2
    assert b"Traceback" not in err
    assert b"Exception ignored" not in err


def test_sigterm_during_compile_leaves_no_temporary_folder(tmp_path: Path) -> None:
    out = tmp_path / "out"
    process = tlmpc(
        "compile",
        "specs/example8.yaml",
        "-o",
        str(out),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert process.stderr is not None
    process.stderr.readline()  # the first progress line: compiling has started
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate()
    assert process.returncode in (0, 143), err
    assert b"Traceback" not in err
    leftovers = [p.name for p in tmp_path.iterdir() if p.name != "out"]
    assert leftovers == []
    if process.returncode == 143:
        assert not out.exists()


def test_ctrl_c_during_start_up_is_130(monkeypatch: pytest.MonkeyPatch) -> None:
    def interrupted(only: str | None = None) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "build_parser", interrupted)
    code, _, err = run_cli("check", "x.yaml")
    assert code == 130
    assert err == "tlmpc: interrupted\n"


def test_sigint_to_a_running_compile_is_130(tmp_path: Path) -> None:
    out = tmp_path / "out"
    process = tlmpc(
        "compile",
        "specs/example8.yaml",
        "-o",
        str(out),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert process.stderr is not None
    process.stderr.readline()  # started: Python's handlers are installed
    process.send_signal(signal.SIGINT)
    _, err = process.communicate()
    assert process.returncode in (0, 130), err
    assert b"Traceback" not in err
    assert [p.name for p in tmp_path.iterdir() if p.name != "out"] == []


def test_control_characters_are_escaped_in_diagnostics(tmp_path: Path) -> None:
    name = "a\x1b[31m\nforged.yaml:1:1: error[X000]: fake\rb.yaml"
    path = tmp_path / name
    path.write_text("version: 1\n")
    code, _, err = run_cli("check", str(path))
    assert code == 1
    assert "\x1b" not in err
    assert "\r" not in err
    assert not any(line.startswith("forged.yaml") for line in err.splitlines())
    assert "\\x1b[31m\\x0aforged" in err


#: The invisible direction and line controls (Unicode Bidi_Control and the two separators),
#: listed here from the Unicode standard, apart from the implementation's own list.
_DIRECTION_CONTROLS = {0x061C, 0x200E, 0x200F, *range(0x202A, 0x202F), *range(0x2066, 0x206A)}
_LINE_SEPARATORS = {0x2028, 0x2029}


def test_printable_escapes_exactly_the_control_characters() -> None:
    for code in [*range(0x250), *range(0x2000, 0x2070), 0x061C, 0x061D]:
        ch = chr(code)
        control = (
            code < 0x20
            or 0x7F <= code <= 0x9F
            or code in _DIRECTION_CONTROLS
            or code in _LINE_SEPARATORS
        )
        assert (printable(ch, keep="") != ch) == control, hex(code)
    diagnostic = error("U001", "bad\nline", file="x\ny", hint="one\ntwo\u202eowt")
    text = diagnostic.format()
    assert text.count("\n") == 1  # only the line that starts the hint: a hint forges no line
    assert "\u202e" not in text
    assert "\\u202e" in text


def test_json_output_is_strict_json() -> None:
    text = json_text({"a": float("inf"), "b": [float("nan"), -float("inf")], "c": 1.5})

    def refuse(constant: str) -> None:
        raise AssertionError(f"non-standard JSON constant {constant}")

    assert json.loads(text, parse_constant=refuse) == {"a": "inf", "b": ["nan", "-inf"], "c": 1.5}


def test_terminal_stream_escapes_what_commands_print() -> None:
    sink = io.StringIO()
    stream = cli.TerminalText(sink, "standard output")
    stream.write("region \x1b[31mred\x1b[0m\r\n")
    assert sink.getvalue() == "region \\x1b[31mred\\x1b[0m\\x0d\n"
