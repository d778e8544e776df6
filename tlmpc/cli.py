"""The ``tlmpc`` command line: ``main(argv) -> exit code``.

Each subcommand lives in its own module under :mod:`tlmpc.commands` with ``NAME``, ``HELP``,
``add_arguments(parser)`` and ``run(args, out, err) -> int``.  Modules import their heavy
dependencies inside ``run`` so that ``tlmpc check`` (a pre-commit hook) starts fast.

Exit codes: 0 success; 1 a valid run with a negative answer (invalid mission, no plan, trace
violates); 2 could not run (usage, unreadable or malformed input); 3 internal error.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import os
import signal
import sys
import threading
import traceback
import typing
from collections.abc import Sequence
from types import ModuleType
from typing import Any, TextIO

from tlmpc import __version__
from tlmpc.artifacts import json_text
from tlmpc.errors import EXIT_INTERNAL, EXIT_USAGE, TlmpcError, best_first, error, printable

#: Subcommand modules, in the order ``--help`` lists them.
COMMAND_MODULES = (
    "compile",
    "check",
    "verify",
    "automaton",
    "export",
    "plot",
    "stage",
    "view",
    "import_map",
    "export_plan",
)

EPILOG = """\
exit codes:
  0  success
  1  valid input, negative answer (invalid mission, no plan, trace violates the task)
  2  could not run (bad flags, unreadable or malformed file)
  3  internal error (please report it with the input that caused it)
"""


def _command(name: str) -> ModuleType:
    return importlib.import_module(f"tlmpc.commands.{name}")


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The argparse parser with every subcommand registered.

    With ``only`` naming a command, only that subcommand is registered (the run parses no
    other; some commands' flags import modules, e.g. ``compile --until`` lists the pipeline's
    stages); with any other ``only`` (a typo), every command is listed, without arguments, so
    that argparse can name the valid choices.
    """
    wanted = only.replace("-", "_") if only is not None and "_" not in only else None
    known = wanted in COMMAND_MODULES
    parser = argparse.ArgumentParser(
        prog="tlmpc",
        description="Temporal logic motion planning compiler and verifier.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"tlmpc {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMAND_MODULES:
        if known and name != wanted:
            continue
        module = _command(name)
        command_parser = sub.add_parser(
            module.NAME,
            help=module.HELP,
            description=getattr(module, "DESCRIPTION", module.HELP),
            epilog=EPILOG,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        if only is None or only == module.NAME:
            module.add_arguments(command_parser)
        command_parser.set_defaults(_run=module.run)
    return parser


def _report(exc: TlmpcError, args: argparse.Namespace, out: TextIO, err: TextIO) -> None:
    diagnostics = best_first(exc.diagnostics)
    if getattr(args, "json", False):
        document = {
            "tool": "tlmpc",
            "version": __version__,
            "command": getattr(args, "command", None),
            "ok": False,
            "diagnostics": [d.to_json() for d in diagnostics],
        }
        out.write(json_text(document))
    for diagnostic in diagnostics:
        err.write(diagnostic.format() + "\n")


class _OutputLost(Exception):
    """Writing to stdout or stderr failed (closed pipe, full disk): the run cannot report."""

    def __init__(self, stream: str, cause: OSError) -> None:
        super().__init__(stream)
        self.stream = stream
        self.cause = cause


class _Terminated(Exception):
    """SIGTERM arrived: unwind like Ctrl-C so temporary folders are removed."""


class TerminalText(io.TextIOBase):
    """A text stream that escapes control characters (ANSI escapes, carriage returns, bells)
    before they reach the terminal or a log, keeping newlines and tabs, and turns a failed
    write into :class:`_OutputLost`."""

    def __init__(self, stream: TextIO, name: str) -> None:
        super().__init__()
        self._stream = stream
        self._name = name

    def write(self, text: str) -> int:
        """Write ``text`` with control characters escaped."""
        try:
            self._stream.write(printable(text))
        except OSError as exc:
            raise _OutputLost(self._name, exc) from None
        return len(text)

    def flush(self) -> None:
        """Flush the wrapped stream."""
        try:
            self._stream.flush()
        except OSError as exc:
            raise _OutputLost(self._name, exc) from None

    def isatty(self) -> bool:
        """Whether the wrapped stream is a terminal."""
        return self._stream.isatty()


def _silence(stream: TextIO) -> None:
    """Point a real standard stream at /dev/null so the interpreter's final flush of what
    could not be written neither fails nor prints a traceback."""
    with contextlib.suppress(OSError, ValueError, AttributeError, io.UnsupportedOperation):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, stream.fileno())
        os.close(devnull)


def _on_sigterm(number: int, frame: object) -> None:
    raise _Terminated


def main(
    argv: Sequence[str] | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Run ``tlmpc`` with ``argv`` (default: ``sys.argv[1:]``); return the exit code.

    Never a traceback for the user's doing: Ctrl-C (also during start-up) exits 130, SIGTERM
    143 after removing temporary folders, a closed or full stdout 2 (with U035 on stderr when
    stderr still works); control characters are escaped in everything printed.
    """
    raw_out = out if out is not None else sys.stdout
    raw_err = err if err is not None else sys.stderr
    safe_out = typing.cast(TextIO, TerminalText(raw_out, "standard output"))
    safe_err = typing.cast(TextIO, TerminalText(raw_err, "standard error"))
    previous: Any = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        code = _main(argv, safe_out, safe_err)
        safe_out.flush()
        safe_err.flush()
        return code
    except KeyboardInterrupt:
        with contextlib.suppress(Exception):
            safe_err.write("tlmpc: interrupted\n")
        return 130
    except _Terminated:
        with contextlib.suppress(Exception):
            safe_err.write("tlmpc: terminated\n")
        return 143
    except _OutputLost as lost:
        _silence(raw_out if lost.stream == "standard output" else raw_err)
        if lost.stream == "standard output" and not isinstance(lost.cause, BrokenPipeError):
            diagnostic = error(
                "U035",
                f"cannot write to {lost.stream}: {lost.cause.strerror or lost.cause}",
                hint="check where the output goes (a full disk? a closed pipe?)",
            )
            with contextlib.suppress(Exception):
                safe_err.write(diagnostic.format() + "\n")
                safe_err.flush()
        return EXIT_USAGE
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _main(argv: Sequence[str] | None, out: TextIO, err: TextIO) -> int:
    words = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(only=next((w for w in words if not w.startswith("-")), None))
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            args = parser.parse_args(None if argv is None else list(argv))
    except SystemExit as exc:  # argparse exits 0 for --help/--version and 2 for bad usage
        return int(exc.code) if isinstance(exc.code, int) else EXIT_USAGE
    try:
        code: int = args._run(args, out, err)
        return code
    except TlmpcError as exc:
        _report(exc, args, out, err)
        return exc.exit_code
    except (KeyboardInterrupt, _Terminated, _OutputLost):
        raise
    except RecursionError:  # a pathological input nested beyond what a stage handles
        err.write(
            error(
                "U036",
                "the input is nested too deeply to process",
                hint="flatten the input (no real mission or trace nests this deep)",
            ).format()
            + "\n"
        )
        return EXIT_USAGE
    except MemoryError:
        err.write(
            error(
                "U037",
                "the input needs more memory than this machine has",
                hint="make the input smaller (fewer regions, a coarser mesh, a shorter trace)",
            ).format()
            + "\n"
        )
        return EXIT_USAGE
    except Exception:  # a bug: say so, never a bare traceback without context
        err.write(
            "tlmpc: internal error (exit 3). Please report it with the input that caused it:\n"
        )
        err.write(traceback.format_exc())
        return EXIT_INTERNAL
