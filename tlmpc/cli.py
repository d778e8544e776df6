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
import errno
import importlib
import io
import os
import re
import signal
import sys
import threading
import typing
import warnings
from collections.abc import Sequence
from types import ModuleType
from typing import Any, TextIO

from tlmpc.base import settled, startup
from tlmpc.base.depth import nesting_room
from tlmpc.base.errors import (
    EXIT_INTERNAL,
    EXIT_USAGE,
    Diagnostic,
    TlmpcError,
    error,
    printable,
)
from tlmpc.base.startup import EXIT_INTERRUPTED, EXIT_TERMINATED
from tlmpc.base.version import __version__
from tlmpc.io.report import Reporter, exit_code_epilog

#: Subcommand modules, in the order ``--help`` lists them.
COMMAND_MODULES = (
    "compile",
    "check",
    "verify",
    "monitor",
    "automaton",
    "export",
    "plot",
    "stage",
    "view",
    "import_map",
    "export_plan",
    "simulate",
    "synth",
    "new",
    "completion",
)

EPILOG = exit_code_epilog()

#: A command-line word that is a value although it starts with `-`: a negative number, or a
#: list of numbers that starts with one (`-33.86,151.21`).
_NEGATIVE_VALUE = re.compile(r"^-\.?\d")


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
        allow_abbrev=False,
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
            # a prefix that names one option today may name another tomorrow (`--json` was
            # taken for `--jsonl`): options are spelled out in full
            allow_abbrev=False,
        )
        # `--georeference -33.86,151.21`, `--transform -1,2,0`: argparse takes a word that
        # starts with `-` for an option unless it looks like a negative number, and its test
        # for one (before Python 3.13) refuses the comma.  No option of tlmpc looks like a
        # number, so every word starting with `-` and a digit is a value, on any Python.
        command_parser._negative_number_matcher = _NEGATIVE_VALUE
        if only is None or only == module.NAME:
            module.add_arguments(command_parser)
        # `_full_parser`: every command's flags (for `tlmpc completion`, which commands cannot
        # import from here: the command line sits above them)
        command_parser.set_defaults(_run=module.run, _full_parser=build_parser)
    return parser


class _OutputLost(Exception):
    """Writing to stdout or stderr failed (closed pipe, full disk): the run cannot report."""

    def __init__(self, stream: str, cause: OSError) -> None:
        super().__init__(stream)
        self.stream = stream
        self.cause = cause


class _Terminated(BaseException):
    """SIGTERM arrived: unwind like Ctrl-C so temporary folders are removed.

    A :class:`BaseException`, like :class:`KeyboardInterrupt`, so that no ``except
    Exception`` on the way (a bag reader's, a library's) takes it for an error of its own."""


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


#: The signals received during the current run (SIGINT, SIGTERM), in order.
_RECEIVED: list[int] = []


def _on_sigterm(number: int, frame: object) -> None:
    if settled.is_settled():
        return  # late: the run's output is in place, it ends with its own code
    _RECEIVED.append(number)
    raise _Terminated


def _on_sigint(number: int, frame: object) -> None:
    if settled.is_settled():
        return
    _RECEIVED.append(number)
    raise KeyboardInterrupt


def _redeliver(previous: Any) -> Any:
    """An unraisable-exception hook that delivers a swallowed signal again.

    A signal handler's exception raised while Python runs a callback it cannot propagate from
    (a weak reference's, a finaliser, an import lock's) is printed as "Exception ignored" and
    dropped, and the run would go on as if nothing happened.  The hook arms a one-shot timer
    instead: its SIGALRM a moment later raises the same exception in ordinary code, where it
    ends the run.  (Sending the signal from here would run its handler inside this hook.)
    """

    def hook(unraisable: Any) -> None:
        exc = unraisable.exc_value
        if isinstance(exc, (KeyboardInterrupt, _Terminated)) and _RECEIVED:
            signal.setitimer(signal.ITIMER_REAL, _REDELIVERY_DELAY)
            return
        previous(unraisable)

    return hook


#: Seconds after a swallowed signal at which it is delivered again.
_REDELIVERY_DELAY = 0.001


def _on_redelivery(number: int, frame: object) -> None:
    if settled.is_settled():
        return  # the swallowed signal came too late to end the run
    raise _signalled() or KeyboardInterrupt()


def _after_the_run(handler: Any) -> Any:
    return signal.SIG_IGN if handler is startup.end_at_once else handler


def _signalled() -> BaseException | None:
    """The exception of the first signal this run received, if any: an exception raised by a
    signal handler inside C code (an extension module being imported, say) may reach us as
    another exception, an ImportError wrapping it; it is still the signal's doing."""
    if not _RECEIVED:
        return None
    return _Terminated() if _RECEIVED[0] == signal.SIGTERM else KeyboardInterrupt()


def run() -> typing.NoReturn:
    """The ``tlmpc`` command: :func:`main` on the process's arguments, then exit with its code.

    After Ctrl-C or SIGTERM (exit 130 or 143) the process ends at once, its streams flushed:
    everything tlmpc wrote or staged has been cleaned up by then, and a normal interpreter
    shutdown can still turn an interrupt it saw into death by SIGINT, losing the documented
    exit code.
    """
    code = main()
    if code in (EXIT_INTERRUPTED, EXIT_TERMINATED):
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(code)
    raise SystemExit(code)


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
    _RECEIVED.clear()
    settled.begin()
    enclosing = _held_outputs()
    handlers = _RunHandlers()
    # Every moment between installing the handlers and restoring them lies inside this outer
    # ``try``: a signal there, in the inner handlers or in the restoring itself, ends the run
    # with its code (a ``finally`` would be outside it, and a signal in it a traceback).
    try:
        try:
            handlers.install()
            code = _main(argv, safe_out, safe_err)
            safe_out.flush()
            safe_err.flush()
            # a signal whose exception a finaliser swallowed, the run over before it came again
            swallowed = None if settled.is_settled() else _signalled()
            if swallowed is not None:
                code = _ended_by(swallowed, safe_err)
        except _OutputLost as lost:
            code = _output_lost(lost, raw_out, raw_err, safe_err)
        except Exception:
            # A signal's exception can come up disguised from where the run starts (the
            # parser imports the command's module): CPython wraps an exception raised in a
            # class's ``__set_name__`` in a RuntimeError, C code in an ImportError.
            disguised = _signalled()
            if disguised is None:
                raise
            code = _ended_by(disguised, safe_err)
        handlers.restore()
        _release_leftovers(enclosing)
        return code
    except (KeyboardInterrupt, _Terminated) as signalled:
        handlers.restore()
        _release_leftovers(enclosing)
        return _ended_by(signalled, safe_err)
    except BaseException:
        handlers.restore()
        _release_leftovers(enclosing)
        raise


def _held_outputs() -> frozenset[Any]:
    """The lock files and staging folders held before this run (by a caller's run)."""
    writer = sys.modules.get("tlmpc.io.outdir")
    return frozenset() if writer is None else frozenset(writer.held())


def _release_leftovers(enclosing: frozenset[Any]) -> None:
    """Remove the lock files and staging folders of this run that a signal cut a ``finally``
    short of removing (only a run that wrote output, and so imported the writer, has any)."""
    writer = sys.modules.get("tlmpc.io.outdir")
    if writer is not None:
        writer.release_leftovers(enclosing)


class _RunHandlers:
    """The command's handlers of SIGTERM, SIGINT and SIGALRM (and its unraisable-exception
    hook) for one run, and what they replaced.

    :meth:`install` records each previous handler before it replaces it, so a signal in the
    middle of installing leaves :meth:`restore` (which may run any number of times) exactly
    what to put back."""

    def __init__(self) -> None:
        self.previous: dict[int, Any] = {}
        self.previous_hook = sys.unraisablehook
        self.hooked = False

    def install(self) -> None:
        """Turn SIGTERM and SIGINT into exceptions that unwind the run (main thread only)."""
        if threading.current_thread() is not threading.main_thread():
            return
        self.hooked = True
        sys.unraisablehook = _redeliver(self.previous_hook)
        self._replace(signal.SIGALRM, _on_redelivery)
        self._replace(signal.SIGTERM, _on_sigterm)
        if signal.getsignal(signal.SIGINT) in (signal.default_int_handler, startup.end_at_once):
            self._replace(signal.SIGINT, _on_sigint)

    def _replace(self, number: int, handler: Any) -> None:
        self.previous[number] = signal.getsignal(number)
        signal.signal(number, handler)

    def restore(self) -> None:
        """Put back what :meth:`install` replaced; a signal from here on is late."""
        # first: a signal while the handlers are put back no longer raises
        settled.settle()
        # The command's own run is over (its output whole or removed): the start-up guard,
        # put back, would turn a finished run into an interrupted one, so a late signal of
        # the command's process is ignored while it exits.
        for number in (signal.SIGTERM, signal.SIGINT):
            if number in self.previous:
                signal.signal(number, _after_the_run(self.previous.pop(number)))
        if self.hooked:
            sys.unraisablehook = self.previous_hook
        if signal.SIGALRM in self.previous:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, self.previous.pop(signal.SIGALRM))


def _output_lost(lost: _OutputLost, raw_out: TextIO, raw_err: TextIO, err: TextIO) -> int:
    """Standard output or error failed: silence it, say so on stderr if that still works."""
    _silence(raw_out if lost.stream == "standard output" else raw_err)
    if lost.stream == "standard output" and not isinstance(lost.cause, BrokenPipeError):
        diagnostic = error(
            "U035",
            f"cannot write to {lost.stream}: {lost.cause.strerror or lost.cause}",
            hint="check where the output goes (a full disk? a closed pipe?)",
        )
        with contextlib.suppress(Exception):
            err.write(diagnostic.format() + "\n")
            err.flush()
    return EXIT_USAGE


def _ended_by(signalled: BaseException, err: TextIO) -> int:
    """Say that Ctrl-C or SIGTERM ended the run; its exit code (130 or 143).

    The run's result is final from here: a signal still on its way (a swallowed one's
    redelivery, armed a moment before) is late, and the run is not ended, nor said to be,
    twice."""
    settled.settle()
    terminated = isinstance(signalled, _Terminated)
    with contextlib.suppress(Exception):
        err.write("tlmpc: terminated\n" if terminated else "tlmpc: interrupted\n")
    return EXIT_TERMINATED if terminated else EXIT_INTERRUPTED


def _input_file(args: argparse.Namespace) -> str | None:
    """The file a command reads its input from, where it takes one (a mission, a spec, a
    map, a trace)."""
    for name in ("mission", "spec", "map", "trace"):
        value = getattr(args, name, None)
        if isinstance(value, list) and len(value) == 1:
            value = value[0]
        if isinstance(value, os.PathLike):
            return str(os.fspath(value))
    return None


#: Why a path the user gave cannot be reached, by ``errno``: a probe such as
#: ``Path.is_file()`` answers False only for a missing entry and lets these through.
_PATH_HINTS = {
    errno.ENAMETOOLONG: "a name in the path is longer than the file system allows "
    "(255 bytes a name on most); shorten it",
    errno.EACCES: "you have no permission to enter a folder of the path or to read the file",
    errno.EPERM: "the operation is not permitted on this path",
    errno.ELOOP: "the path's symbolic links lead back to themselves",
    errno.ENOENT: "check the path",
    errno.ENOTDIR: "a part of the path is a file, not a folder",
    errno.EISDIR: "the path is a folder, not a file",
}


def _unreachable_path(exc: BaseException) -> Diagnostic | None:
    """U001 for an operating-system error on a path the run was given (a name too long, a
    folder it may not enter) that no reader caught, else None: such a path is the user's
    input, not a bug."""
    if not isinstance(exc, OSError) or exc.errno not in _PATH_HINTS or exc.filename is None:
        return None
    path = os.fsdecode(exc.filename)
    return error(
        "U001",
        f"cannot access {path}: {exc.strerror or exc}",
        hint=_PATH_HINTS[exc.errno],
        file=path,
    )


def _main(argv: Sequence[str] | None, out: TextIO, err: TextIO) -> int:
    arguments = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(only=next((w for w in arguments if not w.startswith("-")), None))
    usage = io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(usage):
            args = parser.parse_args(arguments)
    except SystemExit as exc:  # argparse exits 0 for --help/--version and 2 for bad usage
        err.write(usage.getvalue())
        code = int(exc.code) if isinstance(exc.code, int) else EXIT_USAGE
        if code != 0 and "--json" in arguments[: _end_of_options(arguments)]:
            return _usage_envelope(arguments, usage.getvalue(), code, out)
        return code
    err.write(usage.getvalue())
    reporter = Reporter.for_args(args, out, err)
    try:
        with warnings.catch_warnings():
            # Floating-point overflow on extreme inputs is numpy's and shapely's business: the
            # inputs are checked and refused with diagnostics, never with a screen of warnings.
            warnings.filterwarnings("ignore", category=RuntimeWarning)
            with nesting_room():
                result: int = args._run(args, out, err)
        return result
    except TlmpcError as exc:
        return reporter.fail(exc)
    except (KeyboardInterrupt, _Terminated, _OutputLost):
        raise
    except Exception as exc:
        signalled = _signalled()
        if signalled is not None:  # the signal's exception, disguised on its way up
            raise signalled from exc
        if isinstance(exc, RecursionError):  # an input nested beyond what a stage handles
            reporter.diagnose(
                [
                    error(
                        "U036",
                        "the input is nested too deeply to process",
                        hint="flatten the input (no real mission or trace nests this deep)",
                        file=_input_file(args),
                    )
                ]
            )
            return reporter.finish(EXIT_USAGE)
        if isinstance(exc, MemoryError):
            reporter.diagnose(
                [
                    error(
                        "U037",
                        "the input needs more memory than this machine has",
                        hint="make the input smaller (fewer regions, a coarser mesh, a shorter "
                        "trace)",
                    )
                ]
            )
            return reporter.finish(EXIT_USAGE)
        unreachable = _unreachable_path(exc)
        if unreachable is not None:
            reporter.diagnose([unreachable])
            return reporter.finish(EXIT_USAGE)
        # a bug: say so, never a bare traceback without context
        err.write(
            "tlmpc: internal error (exit 3). Please report it with the input that caused it:\n"
        )
        import traceback  # only for a bug's report: not imported on every start

        err.write(traceback.format_exc())
        reporter.diagnose(
            [
                error(
                    "U090",
                    f"internal error: {type(exc).__name__}: {exc}",
                    hint="please report it with the input that caused it (the traceback is above)",
                )
            ]
        )
        return reporter.finish(EXIT_INTERNAL)


def _end_of_options(arguments: list[str]) -> int:
    """Where ``--`` ends the options (a formula or file named ``--json`` after it is data)."""
    return arguments.index("--") if "--" in arguments else len(arguments)


def _usage_envelope(arguments: list[str], message: str, code: int, out: TextIO) -> int:
    """A bad command line with ``--json``: argparse's complaint as a U091 diagnostic."""
    names = {_command(name).NAME for name in COMMAND_MODULES}
    command = next((a for a in arguments if a in names), None)
    lines = [line for line in message.splitlines() if line.strip()]
    reporter = Reporter(command=command, json=True, out=out, err=io.StringIO())
    reporter.diagnose(
        [
            error(
                "U091",
                lines[-1] if lines else "bad command line",
                hint=f"see `tlmpc {command or ''} --help`".replace("  ", " "),
            )
        ]
    )
    return reporter.finish(code)
