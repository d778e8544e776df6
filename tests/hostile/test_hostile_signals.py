"""Ctrl-C and SIGTERM at any moment of a real ``tlmpc compile`` process, start-up included.

Each run gets its signal after a different delay, so the signals land all over the run: in the
interpreter's start-up, in the imports, in the stages, in the writing of OUT, after the end.
Whatever the moment, the run ends in one of these ways and no other:

* exit 130 (Ctrl-C) or 143 (SIGTERM), no traceback, nothing written: neither OUT nor a
  temporary file or lock beside it;
* exit 0, OUT whole (the files of an undisturbed run, each JSON one complete), when the signal
  came after the end;
* killed by the signal itself with nothing on standard error: the interpreter had not started
  running code yet (the shell reports 130/143 all the same);
* for Ctrl-C only: Python's own ``KeyboardInterrupt`` from before the guard of the package's
  first lines was in place (the interpreter's start-up, locating the package, importing the
  guard: no frame of the package past the guard's call) and nothing written;
* for Ctrl-C only: exit 0 and OUT whole after Python's own report of a ``KeyboardInterrupt``
  raised before the guard and dropped by the interpreter (no frame past the guard's call):
  "Exception ignored" from a callback of its import machinery, or "Failed checking if argv[0]
  is an import path entry" from its check of a console script's path, after which it runs
  the script all the same.

The delays are spread over the run; nothing here asserts how long anything took.
"""

from __future__ import annotations

import json
import re
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "tlmpc"
MISSION = ROOT / "specs" / "example1.yaml"

#: A traceback frame: its file and line.
FRAME = re.compile(r'^  File "([^"]+)", line (\d+)', re.MULTILINE)

#: The line of the package's ``__init__`` that installs the guard.
GUARD_LINE = next(
    number
    for number, line in enumerate((PACKAGE / "__init__.py").read_text().splitlines(), start=1)
    if line.startswith("_guard_start()")
)


def _before_the_guard(file: str, line: int) -> bool:
    """Whether a traceback frame is code that runs before the guard is in place."""
    path = Path(file)
    if not path.is_relative_to(PACKAGE):
        return True
    if path == PACKAGE / "__init__.py":
        return line <= GUARD_LINE
    # the guard's own module and the package it sits in, imported by the line above
    return path in (PACKAGE / "base" / "__init__.py", PACKAGE / "base" / "startup.py")


#: Delays (seconds) after the start at which the signal is sent: dense over the start-up.
DELAYS = [0.0, 0.002, 0.005, 0.01, 0.02, 0.03, 0.045, 0.06, 0.08, 0.1, 0.13, 0.16, 0.2, 0.25]
DELAYS += [0.3, 0.4, 0.5, 0.7, 1.0]

#: Further delays, as fractions of an undisturbed run's wall time on this machine now: on a
#: loaded machine the interpreter's start-up alone can outlast every fixed delay above.
FRACTIONS = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8]


def _entry(kind: str) -> list[str]:
    if kind == "module":
        return [sys.executable, "-m", "tlmpc"]
    script = Path(sys.executable).parent / "tlmpc"
    if not script.exists():
        pytest.skip("the tlmpc console script is not installed in this environment")
    return [str(script)]


def _outcome(number: int, code: int, err: str, folder: Path, whole: set[str]) -> str:
    """Which allowed ending this run had; fails the test on any other."""
    left = sorted(p.name for p in folder.iterdir())
    if left != []:  # written: then whole, and the run ended as a finished run
        out = folder / "out"
        assert {p.name for p in out.iterdir()} == whole
        for path in out.glob("*.json"):
            json.loads(path.read_text())
        assert left == ["out"], left
        assert code == 0, (code, err)
        ignored, rest = _ignored_in_the_start_up(number, err)
        assert "Traceback" not in rest, err
        assert "Exception ignored" not in rest, err
        return "finished, the Ctrl-C dropped by the interpreter" if ignored else "finished"
    assert left == [], f"exit {code} left {left}: {err}"
    if code == 128 + number:
        assert "Traceback" not in err, err
        assert "Exception ignored" not in err, err
        return "clean"
    if code == -number and err == "":
        return "before the interpreter ran"
    if err.startswith(INIT_FAILED) and err.rstrip().endswith("<no Python frame>"):
        # a Ctrl-C while CPython installs its own signal handling, before any Python code
        # (no frame at all): the interpreter gives up with its fatal error
        assert number == signal.SIGINT, (code, err)
        return "while the interpreter initialised"
    frames = FRAME.findall(err)
    assert number == signal.SIGINT, (code, err)
    # "KeyboardInterrupt", or "KeyboardInterrupt: " when it came while the interpreter set
    # ``__main__.__loader__`` (it says so on the line before, and exits 1)
    assert re.search(r"KeyboardInterrupt:?$", err.rstrip()), (code, err)
    assert all(_before_the_guard(file, int(line)) for file, line in frames), err
    return "in the interpreter's start-up"


#: How the interpreter reports a Ctrl-C that came while it set up its signal handling.
INIT_FAILED = "Fatal Python error: init_interp_main: can't initialize signals\n"

#: How the interpreter begins its report of an exception it drops in its start-up and goes on:
#: raised in a callback of its import machinery, where an exception cannot propagate, or
#: while it checks whether a script's path is an import path entry (then it runs the script).
DROPPED = r"(?:Exception ignored in: |Failed checking if argv\[0\] is an import path entry\n)"


def _ignored_in_the_start_up(number: int, err: str) -> tuple[bool, str]:
    """Python's own report of a Ctrl-C it dropped before the guard was in place
    (:data:`DROPPED`), split off the rest of standard error."""
    found = re.match(DROPPED + r".*?^KeyboardInterrupt:?[ ]*\n", err, re.S | re.M)
    if found is None:
        return False, err
    assert number == signal.SIGINT, err
    frames = FRAME.findall(found.group(0))
    assert frames, err
    assert all(_before_the_guard(file, int(line)) for file, line in frames), err
    return True, err[found.end() :]


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["script", "module"])
@pytest.mark.parametrize("number", [signal.SIGINT, signal.SIGTERM], ids=["int", "term"])
def test_a_signal_at_any_moment_ends_cleanly(
    tmp_path: Path, kind: str, number: signal.Signals
) -> None:
    reference = tmp_path / "reference"
    started = time.monotonic()
    subprocess.run([*_entry(kind), "compile", str(MISSION), "-o", str(reference)], check=True)
    whole = {p.name for p in reference.iterdir()}
    undisturbed = time.monotonic() - started
    seen: dict[str, int] = {}
    for k, delay in enumerate([*DELAYS, *(f * undisturbed for f in FRACTIONS)]):
        folder = tmp_path / str(k)
        folder.mkdir()
        process = subprocess.Popen(
            [*_entry(kind), "compile", str(MISSION), "-o", str(folder / "out")],
            cwd=folder,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        time.sleep(delay)
        process.send_signal(number)
        _, err = process.communicate()
        outcome = _outcome(number, process.returncode, err, folder, whole)
        seen[outcome] = seen.get(outcome, 0) + 1
    # the delays reach past the imports into the run, whatever the machine's load: runs end by
    # the documented code (every moment of the command's own code: test_hostile_signal_lines)
    assert seen.get("clean", 0) >= len(FRACTIONS) // 2, seen


@pytest.mark.parametrize(
    "heading",
    [
        "Exception ignored in: <function _get_module_lock.<locals>.cb at 0x7f>\n",
        "Failed checking if argv[0] is an import path entry\n",
    ],
)
@pytest.mark.parametrize(
    ("frame", "number", "accepted"),
    [
        ('"<frozen importlib._bootstrap>", line 198, in cb', signal.SIGINT, True),
        (f'"{PACKAGE / "__init__.py"}", line {GUARD_LINE}, in <module>', signal.SIGINT, True),
        (f'"{PACKAGE / "cli.py"}", line 40, in main', signal.SIGINT, False),
        (f'"{PACKAGE / "__init__.py"}", line {GUARD_LINE + 1}, in <module>', signal.SIGINT, False),
        ('"<frozen importlib._bootstrap>", line 198, in cb', signal.SIGTERM, False),
    ],
)
def test_only_a_ctrl_c_dropped_before_the_guard_is_python_s_own(
    heading: str, frame: str, number: signal.Signals, accepted: bool
) -> None:
    """The run that finished after Python dropped a Ctrl-C is accepted only when the dropped
    exception's frames all ran before the guard, and only for Ctrl-C."""
    report = f"{heading}Traceback (most recent call last):\n  File {frame}\nKeyboardInterrupt: \n"
    err = report + "[1/8] load           0.096 s  regions 4\n"
    if accepted:
        assert _ignored_in_the_start_up(number, err) == (True, err[len(report) :])
    else:
        with pytest.raises(AssertionError):
            _ignored_in_the_start_up(number, err)
    assert _ignored_in_the_start_up(number, "[1/8] load\n") == (False, "[1/8] load\n")


def test_a_library_import_installs_no_handler() -> None:
    code = (
        "import signal\n"
        "def handlers(): return signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)\n"
        "before = handlers()\n"
        "import tlmpc, tlmpc.cli\n"
        "print(before == handlers())\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    )
    assert done.stdout.strip() == "True"


@pytest.mark.parametrize(
    ("argv", "orig_argv", "expected"),
    [
        (["/venv/bin/tlmpc", "compile"], ["/venv/bin/python", "/venv/bin/tlmpc", "compile"], True),
        (["C:\\env\\Scripts\\tlmpc.exe"], ["tlmpc.exe"], True),
        (["-m"], ["python3", "-X", "dev", "-m", "tlmpc", "check"], True),
        (["-m"], ["python3", "-m", "tlmpcx"], False),
        (["-m"], ["python3", "-m", "pytest", "tlmpc"], False),
        (["-c"], ["python3", "-c", "import tlmpc", "-m", "tlmpc"], False),
        (["app.py"], ["python3", "app.py", "-m", "tlmpc"], False),
        (["/home/u/tlmpc-tools/run.py"], ["python3", "/home/u/tlmpc-tools/run.py"], False),
    ],
)
def test_the_command_is_recognised_by_how_python_started(
    argv: list[str], orig_argv: list[str], expected: bool
) -> None:
    from tlmpc.base.startup import is_the_command

    assert is_the_command(argv, orig_argv) is expected


class _RaisesInFinaliser:
    """An object whose finaliser receives the signal: Python cannot propagate the handler's
    exception from there and drops it as "Exception ignored"."""

    def __init__(self, number: int) -> None:
        self.number = number

    def __del__(self) -> None:
        signal.raise_signal(self.number)


@pytest.mark.parametrize(("number", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_signal_swallowed_by_a_finaliser_still_ends_the_run(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], number: int, code: int
) -> None:
    import tlmpc.cli

    steps = [0]
    budget = 30_000_000  # seconds of work if nothing ends it

    def run(*args: object) -> int:
        _RaisesInFinaliser(number)  # dropped at once: its finaliser runs here
        while steps[0] < budget:  # ordinary code: the signal must end the run in here
            steps[0] += 1
        return 0

    monkeypatch.setattr("tlmpc.commands.automaton.run", run)
    assert tlmpc.cli.main(["automaton", "G a"]) == code
    assert steps[0] < budget
    assert "Exception ignored" not in capsys.readouterr().err


@pytest.mark.parametrize(("number", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_signal_swallowed_just_before_the_run_returns_still_ends_it(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], number: int, code: int
) -> None:
    # the run is over before the swallowed signal is delivered again: its code is still the
    # signal's (the handlers are given back, the timer that would deliver it cancelled)
    import io

    import tlmpc.cli

    def run(*args: object) -> int:
        _RaisesInFinaliser(number)
        return 0

    monkeypatch.setattr("tlmpc.commands.automaton.run", run)
    err = io.StringIO()
    assert tlmpc.cli.main(["automaton", "G a"], io.StringIO(), err) == code
    assert err.getvalue() == ("tlmpc: terminated\n" if code == 143 else "tlmpc: interrupted\n")
    assert "Exception ignored" not in capsys.readouterr().err


def _signal_after(original: Any, number: int) -> Any:
    """``original``, then the signal: it arrives right after the call created something."""

    def call(*args: Any, **kwargs: Any) -> Any:
        result = original(*args, **kwargs)
        signal.raise_signal(number)
        return result

    return call


@pytest.mark.parametrize("moment", ["lock", "staging"])
def test_a_signal_while_out_is_prepared_leaves_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, moment: str
) -> None:
    import fcntl
    import tempfile

    import tlmpc.cli

    if moment == "lock":  # the lock file exists, its lock is just taken
        monkeypatch.setattr(fcntl, "flock", _signal_after(fcntl.flock, signal.SIGTERM))
    else:  # the staging folder is just made
        monkeypatch.setattr(tempfile, "mkdtemp", _signal_after(tempfile.mkdtemp, signal.SIGTERM))
    code = tlmpc.cli.main(["compile", str(MISSION), "-o", str(tmp_path / "out"), "-q"])
    assert code == 143
    assert list(tmp_path.iterdir()) == []


def test_a_signal_while_a_file_is_replaced_finds_old_or_new(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import tempfile

    from tlmpc.io.outdir import replace_file

    target = tmp_path / "plan.csv"
    target.write_bytes(b"old\n")

    def terminated(number: int, frame: object) -> None:
        raise SystemExit("terminated")

    monkeypatch.setattr(tempfile, "mkstemp", _signal_after(tempfile.mkstemp, signal.SIGTERM))
    previous = signal.signal(signal.SIGTERM, terminated)
    try:
        with pytest.raises(SystemExit):
            replace_file(target, b"new\n")
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert [p.name for p in tmp_path.iterdir()] == ["plan.csv"]
    assert target.read_bytes() in (b"old\n", b"new\n")


@pytest.mark.parametrize(("number", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_the_command_signalled_right_after_the_package_starts_ends_cleanly(
    number: int, code: int
) -> None:
    # a process that is the console script (by its name) receives the signal once the package's
    # first lines ran, while the command's modules are still to be imported
    program = (
        "import os, sys\n"
        "sys.argv[0] = os.path.join('bin', 'tlmpc')\n"
        "import tlmpc\n"
        f"os.kill(os.getpid(), {int(number)})\n"
        "import tlmpc.cli\n"
        "print('went on')\n"
    )
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True)
    assert done.returncode == code, done.stderr
    assert done.stdout == ""
    assert done.stderr == ("tlmpc: terminated\n" if code == 143 else "tlmpc: interrupted\n")


class _FakeSetName:
    """A descriptor whose ``__set_name__`` raises what the handler of ``number`` raises, the way
    a signal arriving inside a class body being created (an import) reaches it."""

    def __init__(self, number: int) -> None:
        self.number = number

    def __set_name__(self, owner: type, name: str) -> None:
        import tlmpc.cli as cli

        handler = cli._on_sigterm if self.number == signal.SIGTERM else cli._on_sigint
        handler(self.number, None)


@pytest.mark.parametrize(("number", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_signal_disguised_by_an_import_while_the_parser_is_built_ends_cleanly(
    monkeypatch: pytest.MonkeyPatch, number: int, code: int
) -> None:
    # CPython 3.11 wraps an exception raised in __set_name__ in a RuntimeError: a signal during
    # the import of a module defining such a class (ipaddress's cached properties, say) came up
    # as that RuntimeError, outside the run's own handlers, and printed a traceback
    import io

    import tlmpc.cli as cli

    def build_parser(only: str | None = None) -> Any:
        type("Imported", (), {"attribute": _FakeSetName(number)})
        raise AssertionError("the signal's exception did not come up")

    monkeypatch.setattr(cli, "build_parser", build_parser)
    out, err = io.StringIO(), io.StringIO()
    previous = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    try:
        assert cli.main(["check", "mission.yaml"], out, err) == code
    finally:
        signal.signal(signal.SIGTERM, previous[0])
        signal.signal(signal.SIGINT, previous[1])
    expected = "terminated" if number == signal.SIGTERM else "interrupted"
    assert err.getvalue() == f"tlmpc: {expected}\n"
