"""The output contract of the CLI: with ``--json`` every command prints exactly one document on
stdout, valid against ``schemas/cli-output.schema.json``; the exit code in it is the process's;
every diagnostic in it was printed on stderr; success, negative answers, unusable input, bad
command lines and internal errors alike.  The exit codes are defined once in code and the
documentation lists the same ones."""

from __future__ import annotations

import argparse
import io
import json
import re
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import COMMAND_MODULES, _command, build_parser, main
from tlmpc.io.report import EXIT_CODES, cli_output_errors

ROOT = Path(__file__).resolve().parent.parent
SPECS = ROOT / "specs"
BAD_MISSION = ROOT / "tests" / "mission" / "bad" / "bow-tie.yaml"


def _strict(text: str) -> Any:
    def refuse(constant: str) -> Any:
        raise ValueError(f"non-finite number {constant} in --json output")

    return json.loads(text, parse_constant=refuse)


def run_json(*argv: str) -> tuple[int, dict[str, Any], str]:
    """Run ``tlmpc ARGV`` and check the contract; the exit code, the envelope, stderr."""
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    document = _strict(out.getvalue())  # exactly one document: trailing text fails here
    assert isinstance(document, dict)
    problems = cli_output_errors(document)
    assert not problems, problems
    assert document["exit_code"] == code
    assert document["ok"] == (code == 0)
    for diagnostic in document["diagnostics"]:
        assert diagnostic["message"].splitlines()[0] in err.getvalue()
    return code, document, err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Example 1 compiled through ``tlmpc compile --json`` (checked as a compile case too)."""
    out = tmp_path_factory.mktemp("contract") / "out"
    code, document, _ = run_json(
        "compile", str(SPECS / "example1.yaml"), "-o", str(out), "-q", "--json"
    )
    assert code == 0
    assert document["command"] == "compile"
    assert document["result"] == json.loads((out / "summary.json").read_text())
    return out


def _copy(compiled: Path, tmp_path: Path) -> Path:
    target = tmp_path / "copy"
    shutil.copytree(compiled, target)
    return target


Case = Callable[[Path, Path], tuple[int, dict[str, Any], str]]

#: For every command with --json: runs that succeed, answer "no", and cannot run.
CASES: dict[str, list[tuple[str, int, Case]]] = {
    "check": [
        ("valid", 0, lambda c, t: run_json("check", str(SPECS / "example1.yaml"), "--json")),
        ("invalid", 1, lambda c, t: run_json("check", str(BAD_MISSION), "--json")),
        ("unreadable", 2, lambda c, t: run_json("check", str(t / "missing.yaml"), "--json")),
    ],
    "compile": [
        (
            "no mission",
            2,
            lambda c, t: run_json("compile", str(t / "missing.yaml"), "-o", str(t / "o"), "--json"),
        ),
        (
            "invalid mission",
            1,
            lambda c, t: run_json("compile", str(BAD_MISSION), "-o", str(t / "o"), "--json"),
        ),
    ],
    "verify": [
        ("satisfied", 0, lambda c, t: run_json("verify", str(c / "trace.json"), "--json")),
        (
            "violated",
            1,
            lambda c, t: run_json(
                "verify",
                str(SPECS / "logs" / "hazard-crossing.csv"),
                "--mission",
                str(SPECS / "reach-avoid.yaml"),
                "--json",
            ),
        ),
        (
            "inconclusive",
            4,
            lambda c, t: run_json(
                "verify",
                str(SPECS / "logs" / "hazard-crossing.csv"),
                "--mission",
                str(SPECS / "example8.yaml"),
                "--json",
            ),
        ),
        ("unreadable", 2, lambda c, t: run_json("verify", str(t / "none.json"), "--json")),
    ],
    "automaton": [
        ("stats", 0, lambda c, t: run_json("automaton", "G F a & G F b", "--stats", "--json")),
        ("automaton", 0, lambda c, t: run_json("automaton", "a U b", "--json")),
        ("next", 1, lambda c, t: run_json("automaton", "X a", "--json")),
    ],
    "stage": [
        ("verify", 0, lambda c, t: run_json("stage", "verify", str(_copy(c, t)), "--json")),
        ("empty dir", 2, lambda c, t: run_json("stage", "simulate", str(t), "--json")),
    ],
    "plot": [
        ("svg", 0, lambda c, t: run_json("plot", str(_copy(c, t)), "--json")),
        ("empty dir", 2, lambda c, t: run_json("plot", str(t), "--json")),
    ],
    "view": [
        ("page", 0, lambda c, t: run_json("view", str(c), "-o", str(t / "v.html"), "--json")),
        ("no input", 2, lambda c, t: run_json("view", "--json")),
    ],
    "simulate": [
        ("run", 0, lambda c, t: run_json("simulate", str(c), "--cycles", "1", "--json")),
        ("cut short", 4, lambda c, t: run_json("simulate", str(c), "--duration", "0.5", "--json")),
        ("empty dir", 2, lambda c, t: run_json("simulate", str(t), "--json")),
    ],
    "synth": [
        (
            "realizable",
            0,
            lambda c, t: run_json("synth", str(_spc(t, "SYSGOAL: []<> y;")), "--json"),
        ),
        (
            "unrealizable",
            1,
            lambda c, t: run_json(
                "synth", str(_spc(t, "SYSTRANS: [](!y');\nSYSGOAL: []<> y;")), "--json"
            ),
        ),
        ("unreadable", 2, lambda c, t: run_json("synth", str(t / "missing.spc"), "--json")),
    ],
}


def _spc(tmp_path: Path, body: str) -> Path:
    """A gr1c specification over one input x and one output y."""
    path = tmp_path / "spec.spc"
    path.write_text(f"ENV: x;\nSYS: y;\n{body}\n")
    return path


CASE_IDS = [(command, name) for command, cases in CASES.items() for name, _, _ in cases]


def _commands_with_json() -> set[str]:
    parser = build_parser()
    names: set[str] = set()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                if any("--json" in a.option_strings for a in sub._actions):
                    names.add(name)
    return names


def test_every_command_with_json_has_cases() -> None:
    assert _commands_with_json() == set(CASES)


@pytest.mark.parametrize(("command", "name"), CASE_IDS, ids=[f"{c}-{n}" for c, n in CASE_IDS])
def test_json_output_follows_the_contract(
    command: str, name: str, compiled: Path, tmp_path: Path
) -> None:
    _, expected, case = next(case for case in CASES[command] if case[0] == name)
    code, document, _ = case(compiled, tmp_path)
    assert code == expected
    assert document["command"] == command
    if code == 0:
        assert document["result"] is not None
        assert not [d for d in document["diagnostics"] if d["severity"] == "error"]
    elif command == "check":  # a result per file, whatever became of each
        assert len(document["result"]["files"]) == 1
        assert any(d["severity"] == "error" for d in document["diagnostics"])
    elif code == 2 or command in ("compile", "automaton"):
        # it could not run (or the input was refused): no result, and an error says why
        assert document["result"] is None
        assert any(d["severity"] == "error" for d in document["diagnostics"])
    elif command == "simulate":  # a run cut short is still reported in full
        assert document["result"]["outcome"] in ("violated", "inconclusive")
    elif command == "synth":  # "unrealizable" comes with its core and counterstrategy
        assert document["result"]["realizable"] is False
        assert document["result"]["core"]
    else:  # a negative or open answer of verify is still a full verdict
        assert document["result"]["verdict"] in ("violated", "inconclusive")


def test_verify_result_is_the_verdict(compiled: Path) -> None:
    _, document, _ = run_json("verify", str(compiled / "trace.json"), "--json")
    assert document["result"] == json.loads((compiled / "verdict.json").read_text())


def test_a_bad_command_line_with_json_is_one_document() -> None:
    code, document, err = run_json("verify", "trace.json", "--json", "--no-such-flag")
    assert code == 2
    assert document["command"] == "verify"
    assert [d["code"] for d in document["diagnostics"]] == ["U091"]
    assert "--no-such-flag" in document["diagnostics"][0]["message"]
    assert "usage:" in err  # argparse's own text still goes to stderr


def test_json_after_double_dash_is_data_not_the_flag() -> None:
    out, err = io.StringIO(), io.StringIO()
    assert main(["automaton", "--no-such-flag", "--", "--json"], out=out, err=err) == 2
    assert out.getvalue() == ""


def test_an_internal_error_is_an_envelope_with_exit_3(monkeypatch: pytest.MonkeyPatch) -> None:
    import tlmpc.automata

    def broken(*args: object, **kwargs: object) -> None:
        raise RuntimeError("broken on purpose")

    monkeypatch.setattr(tlmpc.automata, "translate", broken)
    code, document, err = run_json("automaton", "F a", "--json")
    assert code == 3
    assert [d["code"] for d in document["diagnostics"]] == ["U090"]
    assert "broken on purpose" in document["diagnostics"][0]["message"]
    assert "Traceback" in err
    assert "error[U090]: internal error: RuntimeError: broken on purpose" in err


def test_text_mode_keeps_results_on_stdout_and_status_on_stderr(compiled: Path) -> None:
    out, err = io.StringIO(), io.StringIO()
    assert main(["verify", str(compiled / "trace.json")], out=out, err=err) == 0
    assert out.getvalue().startswith(f"{compiled / 'trace.json'}: satisfied: ")
    assert err.getvalue() == ""
    out, err = io.StringIO(), io.StringIO()
    assert main(["check", str(BAD_MISSION)], out=out, err=err) == 1
    assert out.getvalue() == ""
    assert "error[G004]" in err.getvalue()


def test_exit_codes_are_defined_once_and_documented() -> None:
    codes = [code for code, _ in EXIT_CODES]
    assert len(codes) == len(set(codes))
    docs = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    section = docs.split("## Exit codes", 1)[1].split("\n## ", 1)[0]
    documented = [int(m) for m in re.findall(r"^\| (\d+) \|", section, flags=re.MULTILINE)]
    assert documented == codes
    out = io.StringIO()
    assert main(["--help"], out=out, err=io.StringIO()) == 0
    for code, meaning in EXIT_CODES:
        assert f"{code:>3}  {meaning}" in out.getvalue()
    schema = json.loads((ROOT / "schemas" / "cli-output.schema.json").read_text())
    # the envelope carries every code a run can end with itself (not the signal ones)
    assert set(schema["properties"]["exit_code"]["enum"]) == {c for c in codes if c < 128}


def test_commands_do_not_print_or_pick_exit_codes_themselves() -> None:
    # The reporter owns the streams' results and the exit codes: a command that writes to
    # stdout or returns a literal number bypasses the contract.
    for module_name in COMMAND_MODULES:
        source = Path(_command(module_name).__file__ or "").read_text(encoding="utf-8")
        assert "out.write(" not in source, module_name
        assert "json_text(" not in source or module_name == "automaton", module_name
        assert not re.search(r"^\s+return \d+\s*$", source, flags=re.MULTILINE), module_name


def test_infinite_robustness_is_a_string_in_the_envelope(compiled: Path, tmp_path: Path) -> None:
    trace = json.loads((compiled / "trace.json").read_text())
    trace["ltl"] = "true"  # holds with infinite margin: the robustness is +inf
    path = tmp_path / "trace.json"
    path.write_text(json.dumps(trace))
    code, document, _ = run_json("verify", str(path), "--json")
    assert code == 0
    assert document["result"]["robustness"] == "inf"


def test_a_run_prints_one_document_even_if_it_finishes_twice() -> None:
    # A command that finished and then failed (say, a late I/O error) must not print a second
    # envelope after the first one.
    from tlmpc.base.errors import UsageError, error
    from tlmpc.io.report import Reporter

    out, err = io.StringIO(), io.StringIO()
    reporter = Reporter(command="verify", json=True, out=out, err=err)
    assert reporter.finish(0, {"verdict": "satisfied"}) == 0
    assert reporter.fail(UsageError(error("U001", "late"))) == 2
    assert _strict(out.getvalue())["exit_code"] == 0
    assert "error[U001]: late" in err.getvalue()
