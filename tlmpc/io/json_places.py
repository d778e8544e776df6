"""Where a value of a JSON document is written in its text: JSON paths to line and column.

A diagnostic about a value of a JSON file (a ``trace.json``) names the value by its JSON path
(``$.points[3][0]``, ``$.regions.a``, ``$["odd name"]``); :func:`json_place` finds where the
value starts in the text, as 1-based line and column counted the way Python's ``json`` module
counts them in its own syntax errors (lines end at ``\\n``, columns in characters), so a
document's syntax errors and its value errors point alike.

The text is walked only along the path: each value passed over is skipped by the decoder
itself (C speed), so finding a sample of a large trace costs one parse of what precedes it.
When a key appears twice in an object the last one is found, as ``json.loads`` keeps the last.
A string value's characters are mapped too (:func:`string_char_places`), for a diagnostic
that points inside a string (an LTL formula's syntax error).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Sequence

__all__ = ["json_path", "json_place", "parse_json_path", "string_char_places", "text_place"]

_BLANK = re.compile(r"[ \t\n\r]*")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_STEP = re.compile(r'\.([A-Za-z_][A-Za-z0-9_]*)|\[([0-9]+)\]|\[("(?:[^"\\]|\\.)*")\]')
_DECODER = json.JSONDecoder()
#: The decoder's string scanner (``json.decoder.scanstring``, which typeshed leaves out).
_scan_string: Callable[[str, int], tuple[str, int]] = json.decoder.scanstring  # type: ignore[attr-defined]


def json_path(*keys: str | int) -> str:
    """The JSON path of ``keys`` from the document's root: ``json_path("points", 3, 0)`` is
    ``$.points[3][0]``; a key that is not an identifier is written ``["..."]`` (JSON-quoted)."""
    parts = ["$"]
    for key in keys:
        if isinstance(key, int):
            parts.append(f"[{key}]")
        elif _NAME.match(key):
            parts.append(f".{key}")
        else:
            parts.append(f"[{json.dumps(key)}]")
    return "".join(parts)


def parse_json_path(path: str) -> list[str | int] | None:
    """The keys of a path :func:`json_path` writes (None when ``path`` is not of that form)."""
    if not path.startswith("$"):
        return None
    keys: list[str | int] = []
    position = 1
    while position < len(path):
        step = _STEP.match(path, position)
        if step is None:
            return None
        name, index, quoted = step.groups()
        if name is not None:
            keys.append(name)
        else:
            keys.append(int(index) if index is not None else json.loads(quoted))
        position = step.end()
    return keys


def _blank(text: str, position: int) -> int:
    match = _BLANK.match(text, position)
    return match.end() if match else position


def _value_end(text: str, position: int) -> int:
    return int(_DECODER.raw_decode(text, position)[1])


def _member(text: str, position: int, key: str) -> int | None:
    """Where the value of ``key`` starts in the object at ``position`` (its last occurrence)."""
    found = None
    position = _blank(text, position + 1)
    while position < len(text) and text[position] == '"':
        name, position = _scan_string(text, position + 1)
        position = _blank(text, position)
        if text[position : position + 1] != ":":
            return found
        position = _blank(text, position + 1)
        if name == key:
            found = position
        position = _blank(text, _value_end(text, position))
        if text[position : position + 1] != ",":
            break
        position = _blank(text, position + 1)
    return found


def _item(text: str, position: int, index: int) -> int | None:
    """Where item ``index`` of the array at ``position`` starts."""
    position = _blank(text, position + 1)
    for _ in range(index):
        if text[position : position + 1] == "]":
            return None
        position = _blank(text, _value_end(text, position))
        if text[position : position + 1] != ",":
            return None
        position = _blank(text, position + 1)
    return None if text[position : position + 1] in ("]", "") else position


def value_offset(text: str, keys: Sequence[str | int]) -> int | None:
    """The index in ``text`` where the value at ``keys`` starts; for a key the document lacks,
    where its nearest written parent starts (None when the text is not the JSON it should be)."""
    position = _blank(text, 0)
    try:
        for key in keys:
            opening = text[position : position + 1]
            if isinstance(key, str) and opening == "{":
                found = _member(text, position, key)
            elif isinstance(key, int) and opening == "[":
                found = _item(text, position, key)
            else:
                found = None
            if found is None:
                break
            position = found
    except ValueError:  # the text does not parse along the path
        return None
    return position


def text_place(text: str, offset: int) -> tuple[int, int]:
    """The 1-based line and column of ``text[offset]`` (lines end at ``\\n``, as ``json``'s)."""
    line = text.count("\n", 0, offset) + 1
    return line, offset - text.rfind("\n", 0, offset)


def json_place(text: str, path: str) -> tuple[int, int] | None:
    """Line and column where the value at ``path`` (see :func:`json_path`) starts in the JSON
    ``text``, or its nearest parent's when the document lacks it; None for a path not of
    :func:`json_path`'s form or a text that does not parse along it."""
    keys = parse_json_path(path)
    if keys is None:
        return None
    offset = value_offset(text, keys)
    return None if offset is None else text_place(text, offset)


def string_char_places(text: str, offset: int) -> list[int] | None:
    """For the JSON string starting at ``text[offset]`` (its opening quote), the index in
    ``text`` of each character of its value, and of its closing quote last (so the list is one
    longer than the value); None when no string starts there.

    An escape (``\\n``, ``\\u00e9``) stands for one character written over several; a
    surrogate pair (``\\ud83d\\ude00``) for one character written over twelve."""
    if text[offset : offset + 1] != '"':
        return None
    places: list[int] = []
    position = offset + 1
    while position < len(text):
        char = text[position]
        if char == '"':
            places.append(position)
            return places
        places.append(position)
        if char != "\\":
            position += 1
        elif text[position + 1 : position + 2] != "u":
            position += 2
        else:
            high = _unit(text, position + 2)
            low = _unit(text, position + 8) if text[position + 6 : position + 8] == "\\u" else None
            pair = (
                high is not None
                and 0xD800 <= high <= 0xDBFF
                and low is not None
                and 0xDC00 <= low <= 0xDFFF
            )
            position += 12 if pair else 6
    return None


def _unit(text: str, position: int) -> int | None:
    """The code unit of the four hex digits at ``position`` (None when they are not)."""
    digits = text[position : position + 4]
    if len(digits) != 4 or not all(c in "0123456789abcdefABCDEF" for c in digits):
        return None
    return int(digits, 16)
