"""Where each character of a YAML string's value is written in its file.

A task phrase or an LTL formula is a YAML string, and its diagnostics point at a character of
the string's *value*.  For a one-line plain scalar that character is at the scalar's start
plus its offset.  Otherwise YAML has folded lines, dropped indentation, read escapes (double
quotes) or doubled quotes (single quotes), and the offset says little.  This module walks the
value and the source text together: each non-blank character of the value is matched to the
next piece of source that produces it (a character, an escape sequence such as ``\\"``,
``\\x41`` or ``\\u00e9``, a doubled ``''``); the source between two of them may hold only
blanks, line breaks and escapes of blanks, which YAML folds, drops or keeps.  A blank of the
value, and the end of the value, stand right after the piece matched last.  A block scalar's
text starts on the line after its header (``|``/``>``, its indicators and comment); ``\\`` at
a line end in double quotes continues the line and produces nothing.

When the walk does not add up (a scalar this reading does not follow), there is no mapping,
and callers keep the scalar's start plus the offset.  Lines and columns are 1-based and count
characters, as PyYAML's marks and every diagnostic do.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

__all__ = ["ScalarPlaces", "line_starts", "scalar_places"]

#: What YAML reads as a line break (PyYAML and libyaml alike); "\r\n" is one break.
_BREAK = re.compile("\r\n|[\r\n\x85\u2028\u2029]")
_BREAK_CHARS = "\r\n\x85\u2028\u2029"
#: Double-quoted escapes of one character (YAML 1.1 as PyYAML reads them; "/" is YAML 1.2's).
_ESCAPES = {
    "0": "\0",
    "a": "\x07",
    "b": "\x08",
    "t": "\t",
    "\t": "\t",
    "n": "\n",
    "v": "\x0b",
    "f": "\x0c",
    "r": "\r",
    "e": "\x1b",
    " ": " ",
    '"': '"',
    "/": "/",
    "\\": "\\",
    "N": "\x85",
    "_": "\xa0",
    "L": "\u2028",
    "P": "\u2029",
}
#: Double-quoted escapes by code point: ``\x41``, ``\u00e9``, ``\U0001F600``.
_HEX_DIGITS = {"x": 2, "u": 4, "U": 8}


def line_starts(source: str) -> list[int]:
    """The index in ``source`` where each line starts (YAML's line breaks)."""
    return [0, *(match.end() for match in _BREAK.finditer(source))]


@dataclass(frozen=True, slots=True)
class ScalarPlaces:
    """The 1-based (line, col) in the file of each character of a scalar's value, and of the
    place just after its last character (``places`` has ``len(value) + 1`` entries)."""

    places: tuple[tuple[int, int], ...]
    #: the offset in the value where each of its lines starts (lines end at "\n")
    lines: tuple[int, ...]

    def at_offset(self, offset: int) -> tuple[int, int]:
        """Where the value's character at ``offset`` (0-based) is written."""
        return self.places[min(max(offset, 0), len(self.places) - 1)]

    def __call__(self, line: int, col: int) -> tuple[int, int]:
        """Where the character at 1-based ``line``:``col`` of the value is written, lines and
        columns counted in the value as lark and the phrase and formula readers count them."""
        return self.at_offset(self.lines[min(max(line, 1), len(self.lines)) - 1] + col - 1)


class _Piece(NamedTuple):
    """A piece of source: the character it stands for in the value (None: nothing, a line
    continuation), where it starts and where the place just after it is."""

    produces: str | None
    start: tuple[int, int]
    after: tuple[int, int]


def scalar_places(
    source: str,
    value: str,
    style: str | None,
    start: tuple[int, int],
    end: tuple[int, int],
    lines: Sequence[int] | None = None,
) -> ScalarPlaces | None:
    """Where each character of ``value`` is written in ``source``; None when the walk fails.

    Args:
        source: the whole YAML text.
        value: the scalar's value as the loader read it.
        style: the scalar's style: None or "" plain, "'", '"', "|" or ">".
        start: 0-based (line, column) of the scalar's start mark (its tag or anchor, if any).
        end: 0-based (line, column) of its end mark.
        lines: ``line_starts(source)``, when the caller keeps it for several scalars.
    """
    lines = line_starts(source) if lines is None else lines
    if not 0 <= start[0] < len(lines):
        return None
    begin = lines[start[0]] + start[1]
    stop = min(lines[end[0]] + end[1], len(source)) if end[0] < len(lines) else len(source)
    walked = _pieces(source, begin, stop, (start[0] + 1, start[1] + 1), style or None)
    if walked is None:
        return None
    pieces, first = walked
    places = _match(value, pieces, first)
    if places is None:
        return None
    breaks = (index + 1 for index, char in enumerate(value) if char == "\n")
    return ScalarPlaces(places=tuple(places), lines=(0, *breaks))


class _Walk:
    """A cursor in the source that keeps its 1-based line and column."""

    def __init__(self, source: str, index: int, stop: int, where: tuple[int, int]) -> None:
        self.source = source
        self.index = index
        self.stop = stop
        self.line, self.col = where

    @property
    def where(self) -> tuple[int, int]:
        return self.line, self.col

    def char(self, ahead: int = 0) -> str:
        index = self.index + ahead
        return self.source[index] if index < self.stop else ""

    def step(self) -> None:
        """Move past one character, or one line break."""
        if self.char() in _BREAK_CHARS:
            self.index += 2 if self.source.startswith("\r\n", self.index) else 1
            self.line, self.col = self.line + 1, 1
        else:
            self.index += 1
            self.col += 1


def _pieces(
    source: str, begin: int, stop: int, where: tuple[int, int], style: str | None
) -> tuple[list[_Piece], tuple[int, int]] | None:
    """The pieces of the scalar's text and where its text starts; None when it is not there."""
    walk = _Walk(source, begin, stop, where)
    while walk.char() in ("!", "&"):  # a tag or an anchor before the scalar itself
        while walk.char() and walk.char() not in " \t" + _BREAK_CHARS:
            walk.step()
        while walk.char() in (" ", "\t", "#", *_BREAK_CHARS):
            if walk.char() == "#":  # a comment after the properties
                while walk.char() and walk.char() not in _BREAK_CHARS:
                    walk.step()
            else:
                walk.step()
    if style in ("|", ">"):
        if walk.char() != style:
            return None
        while walk.char() and walk.char() not in _BREAK_CHARS:  # the header and its comment
            walk.step()
        walk.step()
    elif style in ("'", '"'):
        if walk.char() != style:
            return None
        walk.step()
    elif style is not None:
        return None
    first = walk.where
    pieces: list[_Piece] = []
    while walk.char():
        char, at = walk.char(), walk.where
        if style is not None and style in "'\"" and char == style:
            if style == '"' or walk.char(1) != "'":
                break  # the closing quote
            walk.step()  # '' stands for '
        elif style == '"' and char == "\\":
            walk.step()
            escaped = walk.char()
            if escaped in _BREAK_CHARS:  # a line continuation
                walk.step()
                pieces.append(_Piece(None, at, at))
                continue
            if escaped in _HEX_DIGITS:
                digits = source[walk.index + 1 : walk.index + 1 + _HEX_DIGITS[escaped]]
                try:
                    char = chr(int(digits, 16))
                except (ValueError, OverflowError):
                    return None
                for _ in digits:
                    walk.step()
            elif escaped in _ESCAPES:
                char = _ESCAPES[escaped]
            else:
                return None
        elif char in _BREAK_CHARS:
            walk.step()
            pieces.append(_Piece("\n", at, at))  # just after a line's text is its end
            continue
        walk.step()
        pieces.append(_Piece(char, at, walk.where))
    return pieces, first


def _match(
    value: str, pieces: list[_Piece], first: tuple[int, int]
) -> list[tuple[int, int]] | None:
    """The place of each character of ``value`` (and of its end) among ``pieces``."""
    places: list[tuple[int, int]] = []
    after = first  # just after the piece matched last: where a blank of the value stands
    next_piece = 0
    for char in value:
        if char.isspace():
            places.append(after)
            continue
        while next_piece < len(pieces) and pieces[next_piece].produces != char:
            if not _blank(pieces[next_piece]):
                return None  # source text the value does not have: not this scalar
            next_piece += 1
        if next_piece == len(pieces):
            return None
        places.append(pieces[next_piece].start)
        after = pieces[next_piece].after
        next_piece += 1
    if not all(_blank(piece) for piece in pieces[next_piece:]):
        return None
    places.append(after)
    return places


def _blank(piece: _Piece) -> bool:
    return piece.produces is None or piece.produces.isspace()
