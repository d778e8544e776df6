"""Positions in a source text and the reader's diagnostics."""

from __future__ import annotations

import bisect
from dataclasses import dataclass

from tlmpc.base.errors import UsageError, error
from tlmpc.synth.spec import Location


@dataclass(frozen=True)
class Source:
    """A specification's text with 1-based line/column lookup by offset."""

    file: str
    text: str

    def __post_init__(self) -> None:
        starts = [0]
        for index, ch in enumerate(self.text):
            if ch == "\n":
                starts.append(index + 1)
        object.__setattr__(self, "_starts", starts)

    def location(self, offset: int) -> Location:
        """The line and column of ``offset``."""
        starts: list[int] = getattr(self, "_starts")  # noqa: B009 (set in __post_init__)
        line = bisect.bisect_right(starts, offset) - 1
        return Location(self.file, line + 1, offset - starts[line] + 1)

    def fail(self, code: str, message: str, offset: int, hint: str) -> UsageError:
        """An error at ``offset`` (to raise): a specification that cannot be read means that
        synthesis could not run (exit 2), never an answer."""
        where = self.location(offset)
        return UsageError(
            error(code, message, hint=hint, file=self.file, line=where.line, col=where.col)
        )

    def excerpt(self, start: int, end: int) -> str:
        """The source text between two offsets, whitespace collapsed."""
        return " ".join(self.text[start:end].split())
