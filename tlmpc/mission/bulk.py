"""Big flow lists of plain numbers (a 10^6-vertex boundary) read at C speed, located lazily.

PyYAML hands over one Python event object, with two marks, per value: a boundary of 10^6
vertices is four million events and several seconds before any check runs.  Such lists are
almost always written as JSON arrays of decimal numbers, which the C JSON decoder reads in a
fraction of that time.  So, before the YAML parser sees the text, every long flow list of that
form is cut out and replaced by a placeholder scalar laid out over the same lines and columns
(every character outside the list keeps its line and column).  The YAML reader puts the
decoded list where it finds its placeholder as a whole plain value; anything else (a
placeholder inside a comment, a quoted string, a key) makes it read the original text the
ordinary way, so the shortcut can only ever change the speed, never the answer.

Positions inside a list are not stored (that would be millions of entries); :meth:`BulkList.locate`
finds one from the list's text when a diagnostic needs it.
"""

from __future__ import annotations

import gc
import json
import re
from dataclasses import dataclass, field
from itertools import chain
from typing import Any

Path = tuple[str | int, ...]

#: Lists shorter than this (in characters) are left to the YAML reader: they are cheap there.
MIN_CHARS = 4096
#: At most this many numbers are read through the shortcut per document (3·10^6 + 1 for a
#: 10^6-vertex boundary); a bigger document goes the ordinary way, which stops at its own
#: value limit.  Bounds the memory of the decoded lists (~60 bytes a number).
MAX_VALUES = 8_000_000

#: A maximal run of the characters a list of plain decimal numbers is made of.
_RUN = re.compile(r"\[[\[\]0-9.eE,+\- \r\n]{" + str(MIN_CHARS - 1) + ",}")
#: Exponents JSON reads as numbers but YAML 1.1 does not (as text, or out of range): without
#: a sign, without a decimal point in the mantissa, with three digits (may overflow).
_NOT_YAML_EXPONENT = re.compile(r"[eE](?![-+])|[^\d.]\d+[eE]|[eE][-+]\d{3}")
_OPEN = re.compile(r"\[")
_DELIMITER = re.compile(r"[\[\],]")
#: The placeholder's stem; a text that already contains it is read the ordinary way.
STEM = "__tlmpc_bulk_"


def _no_constant(name: str) -> Any:
    raise ValueError(name)


def _integer(text: str) -> int:
    # YAML reads longer integers as too large (see yamlpos): leave those to it.
    if len(text) > 15 + text.startswith("-"):
        raise ValueError(text)
    return int(text)


_DECODER = json.JSONDecoder(parse_constant=_no_constant, parse_int=_integer)


@dataclass(slots=True)
class BulkList:
    """One list cut out of the text: its decoded value and where its text starts."""

    placeholder: str
    text: str
    value: list[Any]
    depth: int
    values: int  # numbers and lists in it, itself included
    points: bool  # every item is a list (a polygon's vertices)
    line: int = 0  # 1-based position of its ``[``, set when the reader meets the placeholder
    col: int = 0
    _starts: list[int] | None = field(default=None, repr=False)

    def locate(self, sub: Path) -> tuple[int, int] | None:
        """Line and column of the value at ``sub`` (indices relative to this list), or of its
        deepest existing ancestor inside the list; None when not even the first step exists."""
        offset: int | None = None
        text = self.text
        for level, index in enumerate(sub):
            if not isinstance(index, int) or index < 0:
                break
            found = self._item(offset or 0, level, index)
            if found is None or text[found] in ",]":  # past the end (or a trailing comma)
                break
            offset = found
            if text[offset] != "[":
                break
        return None if offset is None else self._position(offset)

    def _item(self, start: int, level: int, index: int) -> int | None:
        """Offset of item ``index`` of the list whose ``[`` is at ``start``."""
        text = self.text
        if level == 0 and self.depth == 2 and self.points:
            # Vertices: item i is the (i+1)-th "[" after the outer one (items hold no lists).
            if self._starts is None:
                self._starts = [m.start() for m in _OPEN.finditer(text, 1)]
            return self._starts[index] if index < len(self._starts) else None
        if index == 0:
            return _skip_space(text, start + 1)
        depth = count = 0
        for match in _DELIMITER.finditer(text, start + 1):
            char = match.group()
            if char == "[":
                depth += 1
            elif char == "]":
                if depth == 0:
                    return None
                depth -= 1
            elif depth == 0:
                count += 1
                if count == index:
                    return _skip_space(text, match.end())
        return None

    def _position(self, offset: int) -> tuple[int, int]:
        newline = self.text.rfind("\n", 0, offset)
        if newline < 0:
            return self.line, self.col + offset
        return self.line + self.text.count("\n", 0, offset), offset - newline


def _skip_space(text: str, offset: int) -> int:
    while offset < len(text) and text[offset] in " \r\n":
        offset += 1
    return offset


def _depth_and_count(value: list[Any]) -> tuple[int, int, bool]:
    """Nesting levels of ``value``, the numbers and lists in it (itself included), and
    whether its items are all lists."""
    depth = count = 0
    level = [value]
    points = False
    while level:
        depth += 1
        count += len(level)
        items = list(chain.from_iterable(level))
        kinds = set(map(type, items))
        if depth == 1:
            points = kinds == {list}
        if list not in kinds:
            count += len(items)
            break
        level = items if kinds == {list} else [item for item in items if type(item) is list]
        count += len(items) - len(level)
    return depth, count, points


def _decode(text: str, start: int) -> tuple[Any, int]:
    # The cyclic collector would scan the growing heap again and again while a million
    # small lists are built (it doubles the time); none of them can form a cycle.
    enabled = gc.isenabled()
    gc.disable()
    try:
        return _DECODER.raw_decode(text, start)
    finally:
        if enabled:
            gc.enable()


def cut_out(text: str) -> tuple[str, dict[str, BulkList]]:
    """``text`` with each long list of plain numbers replaced by a placeholder, and the lists.

    Returns ``text`` itself and no lists when there is nothing to cut out.
    """
    if len(text) < MIN_CHARS or STEM in text:
        return text, {}
    pieces: list[str] = []
    lists: dict[str, BulkList] = {}
    budget = MAX_VALUES
    done = 0
    for run in _RUN.finditer(text):
        start = run.start()
        if start < done:
            continue
        if text.count(",", start, run.end()) >= budget:  # too many to decode
            continue
        try:
            value, end = _decode(text, start)
        except (ValueError, RecursionError):
            continue
        if not isinstance(value, list) or end - start < MIN_CHARS:
            # A short list where a run starts (its first item of a list that holds a word,
            # say) stays with the YAML reader: a placeholder longer than a list on one line
            # would move everything after it on that line.
            continue
        span = text[start:end]
        numbers: str | None = span
        if end > run.end():
            # Not numbers only: a mistake deep in a big list ("far", true) is still read in
            # bulk when it is a word JSON and YAML read alike.
            numbers = _only_numbers(span)
        if numbers is None:
            continue
        if ("e" in numbers or "E" in numbers) and _NOT_YAML_EXPONENT.search(numbers):
            continue
        if "\r" in span and span.count("\r") != span.count("\r\n"):
            continue  # a lone carriage return breaks lines differently
        depth, values, points = _depth_and_count(value)
        if values > budget or (numbers is not span and not _plain_words(value)):
            continue
        budget -= values
        placeholder = f"{STEM}{len(lists)}__"
        lists[placeholder] = BulkList(
            placeholder=placeholder,
            text=span,
            value=value,
            depth=depth,
            values=values,
            points=points,
        )
        pieces.append(text[done:start])
        pieces.append(_blank_out(span, placeholder))
        done = end
    if not lists:
        return text, {}
    pieces.append(text[done:])
    return "".join(pieces), lists


_STRING = re.compile(r'"[^"\\]*"')
_WORD = re.compile(r"true|false|null")
_LEFT_OVER = re.compile(r"[^\[\]0-9.eE,+\- \r\n]")


def _only_numbers(span: str) -> str | None:
    """``span`` with its strings and true/false/null taken out, when only numbers remain."""
    if "\\" in span or "{" in span:
        return None  # escapes (YAML has more) and mappings (keys) go the ordinary way
    numbers = _WORD.sub("0", _STRING.sub("0", span))
    return None if _LEFT_OVER.search(numbers) else numbers


def _plain_words(value: list[Any]) -> bool:
    """Whether every text in ``value`` reads alike in JSON and YAML and cannot confuse
    :meth:`BulkList.locate` (no brackets, commas or quotes; printable)."""
    level = [value]
    while level:
        items = list(chain.from_iterable(level))
        for item in items:
            if type(item) is str and (not item.isprintable() or _UNSAFE.search(item)):
                return False
        level = [item for item in items if type(item) is list]
    return True


_UNSAFE = re.compile(r'[\[\],"#:]')


def _blank_out(span: str, placeholder: str) -> str:
    """The placeholder, then ``span``'s line breaks with spaces for everything else."""
    first = span.find("\n")
    if first < 0:
        return placeholder + " " * (len(span) - len(placeholder))
    rest = "\n".join(" " * len(line) for line in span[first + 1 :].split("\n"))
    # The first line may be shorter than the placeholder: nothing else is on it.
    return placeholder + " " * max(0, first - len(placeholder)) + "\n" + rest
