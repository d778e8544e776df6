"""Signals while the ``tlmpc`` command is still starting.

The command spends its first tenths of a second importing (the package, argparse, the
command's module) before :func:`tlmpc.cli.main` installs the handlers that turn Ctrl-C and
SIGTERM into a clean end (temporary files removed, exit 130 or 143).  A signal in that window
used to reach Python's default handler: a ``KeyboardInterrupt`` traceback in the middle of an
import.  The first code of the package installs :func:`guard_start`'s handlers instead when this
process *is* the command; nothing has been written at that point, so they end the process at
once with the documented code.  ``main`` replaces them with its own for the run.

A library user's ``import tlmpc`` changes no signal handler: the guard recognises the command by
how the interpreter was started (the ``tlmpc`` console script, or ``python -m tlmpc``).

The interpreter's own start-up, before the first line of tlmpc runs, is out of any program's
reach: a SIGTERM then kills the process by the signal (the shell reports 143), a Ctrl-C
while Python's ``site`` module runs gets Python's own message, and one raised in a callback of
its import machinery, or while it checks whether a script's path is an import path entry, is
dropped by Python ("Exception ignored", "Failed checking if argv[0] is an import path entry"),
the run going on.
"""

from __future__ import annotations

# The C module under ``signal``: ``signal.py`` itself imports ``enum``, a few milliseconds in
# which a Ctrl-C would still meet Python's default handler.  Only built-in modules here.
import _signal  # type: ignore[import-not-found]
import os
import sys

#: Exit codes of a run ended by Ctrl-C and by SIGTERM (128 + the signal's number).
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143

#: The names a console-script launcher of ``tlmpc`` has on POSIX and Windows.
COMMAND_NAMES = frozenset({"tlmpc", "tlmpc.exe", "tlmpc-script.py", "tlmpc-script.pyw"})


def is_the_command(argv: list[str], orig_argv: list[str]) -> bool:
    """Whether this interpreter was started as the ``tlmpc`` command: its console script, or
    ``python [options] -m tlmpc`` (``argv`` is ``sys.argv``, ``orig_argv`` ``sys.orig_argv``)."""
    # the launcher's file name, from a POSIX or a Windows path
    if argv and argv[0].replace("\\", "/").rsplit("/", 1)[-1] in COMMAND_NAMES:
        return True
    words = iter(orig_argv[1:])
    for word in words:
        if word == "-m":
            return next(words, None) == "tlmpc"
        if word in ("-X", "-W"):
            next(words, None)  # the option's value
        elif word in ("-c", "-") or not word.startswith("-"):
            return False  # a program, a script or stdin: not the command
    return False


def end_at_once(number: int, frame: object) -> None:
    """A signal before the command has written anything: say so and exit 130 or 143 now."""
    terminated = number == _signal.SIGTERM
    message = b"tlmpc: terminated\n" if terminated else b"tlmpc: interrupted\n"
    try:  # noqa: SIM105 (contextlib is not loaded yet, and this runs before anything else)
        os.write(2, message)
    except OSError:
        pass  # no standard error to tell: the exit code still does
    os._exit(EXIT_TERMINATED if terminated else EXIT_INTERRUPTED)


def guard_start() -> bool:
    """Install :func:`end_at_once` for SIGINT and SIGTERM when this process is the command
    (and this is its main thread, where Python runs signal handlers); return whether it did."""
    if not is_the_command(sys.argv, getattr(sys, "orig_argv", [])):
        return False
    # a signal ignored by whoever started us (nohup, a background job) stays ignored
    if _signal.getsignal(_signal.SIGINT) is _signal.default_int_handler:
        _signal.signal(_signal.SIGINT, end_at_once)
    if _signal.getsignal(_signal.SIGTERM) == _signal.SIG_DFL:
        _signal.signal(_signal.SIGTERM, end_at_once)
    return True
