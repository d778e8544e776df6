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
import json
import sys
import traceback
from collections.abc import Sequence
from types import ModuleType
from typing import TextIO

from tlmpc import __version__
from tlmpc.errors import EXIT_INTERNAL, EXIT_USAGE, TlmpcError, best_first

#: Subcommand modules, in the order ``--help`` lists them.
COMMAND_MODULES = (
    "compile",
    "check",
    "verify",
    "automaton",
    "export",
    "plot",
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


def build_parser() -> argparse.ArgumentParser:
    """The argparse parser with every subcommand registered."""
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
        module = _command(name)
        command_parser = sub.add_parser(
            module.NAME,
            help=module.HELP,
            description=getattr(module, "DESCRIPTION", module.HELP),
            epilog=EPILOG,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
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
        out.write(json.dumps(document, indent=2, sort_keys=True) + "\n")
    for diagnostic in diagnostics:
        err.write(diagnostic.format() + "\n")


def main(
    argv: Sequence[str] | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Run ``tlmpc`` with ``argv`` (default: ``sys.argv[1:]``); return the exit code."""
    out = out if out is not None else sys.stdout
    err = err if err is not None else sys.stderr
    parser = build_parser()
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
    except KeyboardInterrupt:
        err.write("tlmpc: interrupted\n")
        return 130
    except Exception:  # a bug: say so, never a bare traceback without context
        err.write(
            "tlmpc: internal error (exit 3). Please report it with the input that caused it:\n"
        )
        err.write(traceback.format_exc())
        return EXIT_INTERNAL
