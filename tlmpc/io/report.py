"""The output contract of every ``tlmpc`` command: what goes where, and the exit code.

One :class:`Reporter` per run owns the two streams.  Diagnostics, progress and status lines
go to standard error; the command's result goes to standard output, as text, or with
``--json`` as exactly one JSON document, the *envelope* (``schemas/cli-output.schema.json``)::

    {"format": "tlmpc.cli/1", "tool": "tlmpc", "version": "...", "command": "verify",
     "ok": true, "exit_code": 0, "diagnostics": [...], "result": {...}}

``result`` is the command's own document (a verdict for ``verify``, the summary for
``compile``...) or ``null`` when the command failed before it had one.  The envelope is
strict JSON: non-finite numbers are written as the strings ``"inf"``, ``"-inf"``, ``"nan"``.

Commands call :meth:`Reporter.finish` (or :meth:`Reporter.fail` for errors) once and return
what it returns, so exit codes are chosen here and nowhere else.  The codes and their meaning
are :data:`EXIT_CODES` (``docs/cli.md`` lists the same table; a test compares them).
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any, TextIO

from tlmpc.base.errors import (
    EXIT_INCONCLUSIVE,
    EXIT_INTERNAL,
    EXIT_NEGATIVE,
    EXIT_OK,
    EXIT_USAGE,
    Diagnostic,
    TlmpcError,
    best_first,
    printable,
)
from tlmpc.base.startup import EXIT_INTERRUPTED, EXIT_TERMINATED

#: Every exit code of every command, with its meaning (the one definition; ``--help`` and
#: ``docs/cli.md`` show this table).
EXIT_CODES: tuple[tuple[int, str], ...] = (
    (EXIT_OK, "success"),
    (EXIT_NEGATIVE, "valid input, negative answer (invalid mission, no plan, trace violates)"),
    (EXIT_USAGE, "could not run (bad flags, unreadable or malformed file)"),
    (EXIT_INTERNAL, "internal error (please report it with the input that caused it)"),
    (EXIT_INCONCLUSIVE, "verify: a log that may go on is neither satisfied nor violated yet"),
    (EXIT_INTERRUPTED, "interrupted (Ctrl-C); temporary files are removed, OUT is untouched"),
    (EXIT_TERMINATED, "terminated (SIGTERM); temporary files are removed, OUT is untouched"),
)

#: The ``format`` of the ``--json`` envelope.
CLI_FORMAT = "tlmpc.cli/1"

#: How a verdict's outcome maps to the exit code of ``tlmpc verify``.
OUTCOME_EXIT = {
    "satisfied": EXIT_OK,
    "violated": EXIT_NEGATIVE,
    "inconclusive": EXIT_INCONCLUSIVE,
}


def exit_code_epilog() -> str:
    """The ``exit codes:`` block shown at the end of ``--help``."""
    rows = [f"  {code:>3}  {meaning}" for code, meaning in EXIT_CODES]
    return "exit codes:\n" + "\n".join(rows) + "\n"


@dataclass
class Reporter:
    """The output of one command run (see the module docstring for the contract)."""

    command: str | None
    json: bool
    out: TextIO
    err: TextIO
    diagnostics: list[Diagnostic] = field(default_factory=list)
    finished: bool = False
    #: the hints printed so far: each is printed once per run (the envelope keeps them all)
    hinted: set[str] = field(default_factory=set)

    @classmethod
    def for_args(cls, args: argparse.Namespace, out: TextIO, err: TextIO) -> Reporter:
        """The reporter of a parsed command line (``--json`` when the command has the flag).

        One per run: the command and the CLI's error handling share it, so the envelope of a
        run that fails half-way still carries every diagnostic printed before the failure.
        """
        existing = getattr(args, "_reporter", None)
        if isinstance(existing, Reporter):
            return existing
        reporter = cls(
            command=getattr(args, "command", None),
            json=bool(getattr(args, "json", False)),
            out=out,
            err=err,
        )
        args._reporter = reporter
        return reporter

    def diagnose(self, diagnostics: Iterable[Diagnostic]) -> None:
        """Print diagnostics on standard error (and keep them for the JSON envelope).

        Warnings alike but for names and numbers are printed as one line
        (:func:`tlmpc.io.aggregate.aggregate`); a hint is printed with the first diagnostic
        of the run that has it, not again (a plan refused at ten corners gets one long hint,
        not ten); the envelope keeps each diagnostic with its hint.
        """
        from tlmpc.io.aggregate import aggregate

        batch = list(diagnostics)
        self.diagnostics.extend(batch)
        for diagnostic in aggregate(batch):
            hint = diagnostic.hint
            if hint is not None and hint in self.hinted:
                diagnostic = replace(diagnostic, hint=None)
            elif hint is not None:
                self.hinted.add(hint)
            self.err.write(diagnostic.format() + "\n")

    def note(self, text: str) -> None:
        """A status or progress line on standard error (never part of the result): one line,
        whatever the names it quotes hold (a newline in a file name is escaped, as in a
        diagnostic, so no name can start a line that reads like one)."""
        self.err.write(printable(text, keep="") + "\n")
        self.err.flush()

    def stream(self, text: str) -> None:
        """A line of the result printed as soon as it is known (a batch's log that finished,
        a monitor's verdict that changed): on standard output in text mode; with ``--json``
        on standard error, since the envelope is all standard output holds."""
        target = self.err if self.json else self.out
        target.write(text + "\n")
        target.flush()

    def finish(
        self, exit_code: int, result: Mapping[str, Any] | None = None, text: str = ""
    ) -> int:
        """End the run: the envelope with ``result`` (``--json``) or ``text`` on standard
        output; returns ``exit_code`` for the command to return.

        A second call prints nothing more: stdout holds one document whatever happens after.
        """
        if self.finished:
            return exit_code
        self.finished = True
        if self.json:
            self.out.write(self.envelope(exit_code, result))
        elif text:
            self.out.write(text)
        return exit_code

    def fail(self, error: TlmpcError) -> int:
        """End the run with the diagnostics of ``error`` and its exit code."""
        self.diagnose(best_first(error.diagnostics))
        return self.finish(error.exit_code)

    def envelope(self, exit_code: int, result: Mapping[str, Any] | None) -> str:
        """The ``--json`` document, as text."""
        from tlmpc.base.version import __version__
        from tlmpc.io.artifacts import json_text

        document = {
            "format": CLI_FORMAT,
            "tool": "tlmpc",
            "version": __version__,
            "command": self.command,
            "ok": exit_code == EXIT_OK,
            "exit_code": exit_code,
            "diagnostics": [d.to_json() for d in self.diagnostics],
            "result": dict(result) if result is not None else None,
        }
        return json_text(document)


def cli_output_errors(document: Any) -> list[str]:
    """Messages for every way ``document`` violates ``schemas/cli-output.schema.json``
    (whose ``result`` refers to the artifact schemas by their ``$id``)."""
    import jsonschema
    from referencing import Registry, Resource

    from tlmpc.io.schema_check import load_schema, schema_dir

    resources = []
    for path in sorted(schema_dir().glob("*.schema.json")):
        schema = load_schema(path.name.removesuffix(".schema.json"))
        resources.append((schema["$id"], Resource.from_contents(schema)))
    registry: Registry[Any] = Registry().with_resources(resources)
    validator = jsonschema.Draft202012Validator(load_schema("cli-output"), registry=registry)
    errors = sorted(validator.iter_errors(document), key=lambda e: str(list(e.absolute_path)))
    return [f"{'/'.join(str(p) for p in e.absolute_path) or '$'}: {e.message}" for e in errors]
