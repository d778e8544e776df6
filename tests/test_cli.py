"""The command-line shell: help, version, usage errors, exit codes."""

from __future__ import annotations

import io

import pytest

from tlmpc.base.version import __version__
from tlmpc.cli import COMMAND_MODULES, _command, build_parser, main


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def test_help_lists_every_command_and_the_exit_codes() -> None:
    code, out, _ = run("--help")
    assert code == 0
    for name in COMMAND_MODULES:
        assert _command(name).NAME in out  # module import_map is command import-map
    assert "exit codes" in out
    assert "3  internal error" in out


def test_version() -> None:
    code, out, _ = run("--version")
    assert code == 0
    assert __version__ in out


@pytest.mark.parametrize(
    "argv", [(), ("frobnicate",), ("compile",), ("compile", "x", "--until", "nope")]
)
def test_usage_errors_exit_2(argv: tuple[str, ...]) -> None:
    code, _, err = run(*argv)
    assert code == 2
    assert "usage:" in err


@pytest.mark.parametrize(
    ("argv", "prefix"),
    [
        (("monitor", "--mission", "m.yaml", "--json"), "--json"),
        (("compile", "m.yaml", "--unt", "plan"), "--unt"),
        (("verify", "trace.json", "--miss", "m.yaml"), "--miss"),
    ],
)
def test_a_prefix_of_an_option_is_not_taken_for_it(argv: tuple[str, ...], prefix: str) -> None:
    # `monitor --json` once ran as `--jsonl`: a prefix may name another option tomorrow
    code, _, err = run(*argv)
    assert code == 2
    assert f"unrecognized arguments: {prefix}" in err


@pytest.mark.parametrize(
    ("command", "argv", "dest", "value"),
    [
        (
            "verify",
            ["x.csv", "--mission", "m.yaml", "--transform", "-1,2,0"],
            "transform",
            "-1,2,0",
        ),
        ("plot", ["out", "--zoom", "-5,-5,5,5"], "zoom", (-5.0, -5.0, 5.0, 5.0)),
        ("monitor", ["--mission", "m.yaml", "--transform", "-.5,0,0"], "transform", "-.5,0,0"),
    ],
)
def test_a_value_starting_with_a_negative_number_is_a_value(
    command: str, argv: list[str], dest: str, value: object
) -> None:
    # argparse before Python 3.13 took `-1,2,0` for an option
    parsed = build_parser(command).parse_args([command, *argv])
    assert getattr(parsed, dest) == value


def test_missing_mission_file_exits_2(tmp_path: object) -> None:
    code, _, err = run("compile", "/nonexistent/mission.yaml", "-o", "/tmp/tlmpc-never-written")
    assert code == 2
    assert "error[U" in err


def test_internal_errors_exit_3_with_a_report_hint(monkeypatch: pytest.MonkeyPatch) -> None:
    import tlmpc.commands.compile as compile_command

    def explode(*_: object, **__: object) -> int:
        raise ZeroDivisionError("boom")

    monkeypatch.setattr(compile_command, "run", explode)
    code, _, err = run("compile", "whatever.yaml")
    assert code == 3
    assert "internal error" in err
    assert "ZeroDivisionError" in err
