"""Diagnostics and the exception hierarchy shared by every stage.

A :class:`Diagnostic` is one problem with a location, a stable code and a hint.  Stages collect
all the diagnostics they can find and raise one :class:`TlmpcError` carrying them, best first;
the CLI prints them as ``FILE:LINE:COL: error[CODE]: message`` followed by ``  hint: ...``.

Code prefixes, one per stage (the full list is in ``docs/errors.md``):

====  ==================================================
 U    usage and I/O (unreadable file, bad flags)
 Y    YAML syntax and structure (duplicate keys)
 S    schema violations of a mission or artifact
 G    geometry of the workspace and regions
 L    LTL formulas
 T    task phrases
 A    abstraction (triangulation, transition system)
 B    Büchi automata (translation, HOA reading)
 P    planning (no plan explanations)
 C    control synthesis
 V    verification of traces
 I    internal errors (bugs)
====  ==================================================
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Literal

Severity = Literal["error", "warning", "note"]

#: Exit codes of every ``tlmpc`` command (documented in ``docs/cli.md``).
EXIT_OK = 0
EXIT_NEGATIVE = 1  # ran fine, the answer is "no": invalid mission, no plan, trace violates
EXIT_USAGE = 2  # could not run: bad flags, unreadable input, bad trace file
EXIT_INTERNAL = 3  # a bug or a solver failure
EXIT_INCONCLUSIVE = 4  # ran fine, no answer yet: a log whose continuation decides (verify)


#: Characters that reorder or break the text around them without being seen: Unicode
#: direction controls (a name ``abc\u202etxt.exe`` shows as ``abcexe.txt``), and the line and
#: paragraph separators some viewers break lines at.
_INVISIBLE = frozenset(
    "\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069\u2028\u2029"
)

#: Code point ranges ``(first, last)``, in increasing order, of the characters no printed or
#: exported name carries as they are: control characters (C0, DEL, C1), the invisible
#: direction and line controls, lone surrogates (no UTF-8 file can hold one, yet an escaped
#: ``\ud800`` in a JSON input reads back as one) and the Unicode noncharacters (U+FFFE and
#: U+FFFF are not XML 1.0 characters: one makes a whole SVG unreadable).  The one rule behind
#: :func:`is_unsafe_char` and :func:`printable`; the view's page escapes these same ranges.
UNSAFE_RANGES: tuple[tuple[int, int], ...] = tuple(
    sorted(
        [
            (0x00, 0x1F),
            (0x7F, 0x9F),
            *((ord(ch), ord(ch)) for ch in _INVISIBLE),
            (0xD800, 0xDFFF),
            (0xFDD0, 0xFDEF),
            *((plane + 0xFFFE, plane + 0xFFFF) for plane in range(0, 0x110000, 0x10000)),
        ]
    )
)
_UNSAFE_FIRSTS = tuple(first for first, _ in UNSAFE_RANGES)


def is_unsafe_char(ch: str) -> bool:
    """Whether ``ch`` is a control character (C0, DEL, C1), an invisible direction or line
    control, a lone surrogate or a noncharacter (:data:`UNSAFE_RANGES`): the characters no
    exported or printed name may carry as they are."""
    code = ord(ch)
    index = bisect_right(_UNSAFE_FIRSTS, code) - 1
    return index >= 0 and code <= UNSAFE_RANGES[index][1]


def printable(text: str, keep: str = "\n\t") -> str:
    """``text`` with control characters (C0 but ``keep``, DEL, C1), invisible direction and
    line controls, lone surrogates and noncharacters as ``\\xNN`` / ``\\uNNNN`` /
    ``\\UNNNNNNNN`` escapes.

    The one sanitiser of everything tlmpc prints (diagnostics, hints, status lines) and of
    names written into exported text and pictures (SVG, PNG, HTML): a hostile name can neither
    forge a line, drive the terminal, reorder what is shown, nor make a file unreadable."""
    if text.isprintable():  # no unsafe character at all (newlines and tabs included)
        return text
    return "".join(ch if ch in keep or not is_unsafe_char(ch) else _escaped(ch) for ch in text)


def _escaped(ch: str) -> str:
    code = ord(ch)
    if code < 0x100:
        return f"\\x{code:02x}"
    return f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


@dataclass(frozen=True, slots=True, kw_only=True)
class Diagnostic:
    """One problem found in the user's input, with where it is and what to do about it.

    ``line`` and ``col`` are 1-based; ``path`` is a JSON path into the document
    (``$.regions.p1``) when the problem belongs to a value rather than to text.
    """

    code: str
    message: str
    hint: str | None = None
    file: str | None = None
    line: int | None = None
    col: int | None = None
    path: str | None = None
    severity: Severity = "error"

    def location(self) -> str:
        """``file:line:col`` with whatever parts are known (``<input>`` when no file)."""
        parts = [self.file or "<input>"]
        if self.line is not None:
            parts.append(str(self.line))
            if self.col is not None:
                parts.append(str(self.col))
        return ":".join(parts)

    def format(self) -> str:
        """The human form: ``FILE:LINE:COL: error[CODE]: message`` and an indented hint.

        Control characters are escaped (newlines too, in the file name, message and hint), so
        a hostile name can neither forge a diagnostic line nor drive the terminal."""
        location = printable(self.location(), keep="")
        text = f"{location}: {self.severity}[{self.code}]: {printable(self.message, keep='')}"
        if self.hint:
            text += f"\n  hint: {printable(self.hint, keep='')}"
        return text

    def to_json(self) -> dict[str, Any]:
        """A JSON-able dict (keys with no value are left out)."""
        data: dict[str, Any] = {
            "code": self.code,
            "severity": self.severity,
            "message": self.message,
        }
        for key in ("hint", "file", "line", "col", "path"):
            value = getattr(self, key)
            if value is not None:
                data[key] = value
        return data

    def sort_key(self) -> tuple[int, str, int, int, str]:
        """Order used for "best first": errors before warnings, then by position."""
        rank = {"error": 0, "warning": 1, "note": 2}[self.severity]
        return (rank, self.file or "", self.line or 0, self.col or 0, self.code)


class TlmpcError(Exception):
    """Base of every error tlmpc raises on purpose; carries one or more diagnostics."""

    exit_code: int = EXIT_NEGATIVE

    def __init__(self, diagnostics: Diagnostic | Iterable[Diagnostic]) -> None:
        if isinstance(diagnostics, Diagnostic):
            diagnostics = [diagnostics]
        self.diagnostics: tuple[Diagnostic, ...] = tuple(diagnostics)
        if not self.diagnostics:
            raise ValueError(f"{type(self).__name__} needs at least one diagnostic")
        super().__init__("\n".join(d.format() for d in self.diagnostics))


class InvalidInputError(TlmpcError):
    """The user's mission, formula or trace is invalid (exit 1)."""


class UsageError(TlmpcError):
    """The command could not run: bad flags, unreadable or malformed file (exit 2)."""

    exit_code = EXIT_USAGE


class NoPlanError(TlmpcError):
    """The mission is valid but no trajectory can satisfy it; diagnostics say why (exit 1)."""


class SolverError(TlmpcError):
    """A numerical solver failed where it should not have (exit 3)."""

    exit_code = EXIT_INTERNAL


def error(
    code: str,
    message: str,
    *,
    hint: str | None = None,
    file: str | None = None,
    line: int | None = None,
    col: int | None = None,
    path: str | None = None,
) -> Diagnostic:
    """Shorthand for an error-severity :class:`Diagnostic`."""
    return Diagnostic(
        code=code, message=message, hint=hint, file=file, line=line, col=col, path=path
    )


def best_first(diagnostics: Iterable[Diagnostic]) -> list[Diagnostic]:
    """Sort diagnostics errors-first, then by file position; drop exact duplicates."""
    unique = list(dict.fromkeys(diagnostics))
    return sorted(unique, key=Diagnostic.sort_key)
