"""Where a character of a formula or a task phrase is written in its file.

A formula or a phrase is a string of a mission; its readers count lines and columns in the
string (1-based), diagnostics in the file.  The string starts at a known line and column: its
first line continues from there, and each further line starts at column 1 of the next line of
the file.  Where that is not exact (a YAML string over several lines, quoted or a block), the
caller passes a :data:`Place` that knows where each character is written
(:mod:`tlmpc.io.scalar_places`).
"""

from __future__ import annotations

from collections.abc import Callable

#: Where the character at a 1-based line and column of the string is written in the file.
Place = Callable[[int, int], tuple[int, int]]


def placed(
    line: int, column: int, start: tuple[int, int], place: Place | None = None
) -> tuple[int, int]:
    """Where the string's character at ``line``:``column`` is written, for a string starting at
    ``start`` (line, column) of its file, or as ``place`` says when given."""
    if place is not None:
        return place(line, column)
    if line == 1:
        return start[0], start[1] + column - 1
    return start[0] + line - 1, column
