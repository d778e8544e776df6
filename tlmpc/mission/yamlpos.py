"""YAML to plain data with a position for every value, key and list item.

PyYAML silently keeps the last of two equal keys and gives positions only on its node graph,
so we compose the node graph ourselves, convert it to plain data and record, for every JSON
path, where its value and (for mapping entries) its key start.  Duplicate keys, alias bombs,
too deep nesting and non-finite numbers become diagnostics instead of surprises.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

import yaml

from tlmpc.base.errors import Diagnostic, error
from tlmpc.io import json_places
from tlmpc.io.inputs import foreign_line_break, yaml_error
from tlmpc.io.scalar_places import ScalarPlaces, line_starts, scalar_places
from tlmpc.mission.bulk import STEM, BulkList, cut_out

Path = tuple[str | int, ...]

#: libyaml's loader when PyYAML was built with it (ten times faster), same nodes and marks.
_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

#: Refuse documents that expand to more values than this (a "billion laughs" alias bomb, or
#: a map too large to check in seconds); a 10^5-vertex boundary has 300,001.
MAX_NODES = 1_000_000
#: Refuse nesting deeper than this (no mission nests more than 6 levels).
MAX_DEPTH = 64


@dataclass(slots=True)
class PositionedDocument:
    """Plain data plus 1-based (line, col) positions keyed by JSON path."""

    data: Any
    values: dict[Path, tuple[int, int]] = field(default_factory=dict)
    keys: dict[Path, tuple[int, int]] = field(default_factory=dict)
    quoted: dict[Path, bool] = field(default_factory=dict)
    block: dict[Path, bool] = field(default_factory=dict)
    #: Long number lists read in bulk: positions inside them are found on demand.
    bulk: dict[Path, BulkList] = field(default_factory=dict)
    #: Containers whose plain numbers, keys or containers were read without their positions
    #: (``lazy`` reading: only what the top-level mapping holds is placed) ...
    unplaced: set[Path] = field(default_factory=set)
    #: ... and how to read the whole document again with every position, when one is asked.
    reread: Callable[[], PositionedDocument | None] | None = None
    #: The YAML text, and for each string that is quoted, a block or over several lines:
    #: (value, style, 0-based start and end marks), to place its characters (see places).
    source: str = ""
    scalars: dict[Path, tuple[str, str | None, tuple[int, int], tuple[int, int]]] = field(
        default_factory=dict
    )
    _lines: list[int] | None = None
    _places: dict[Path, ScalarPlaces | None] = field(default_factory=dict)

    def value_at(self, path: Path) -> tuple[int, int]:
        """Position of the value at ``path``, or of its deepest known ancestor."""
        for cut in range(len(path), -1, -1):
            prefix = path[:cut]
            if cut < len(path) and prefix in self.unplaced and self.reread is not None:
                self._place_all()
                return self.value_at(path)
            if prefix in self.values:
                inside = self.bulk[prefix].locate(path[cut:]) if prefix in self.bulk else None
                return inside or self.values[prefix]
        return (1, 1)

    def _place_all(self) -> None:
        """Take every position from a reading that records them all (diagnostics only)."""
        full = self.reread() if self.reread is not None else None
        self.reread = None
        self.unplaced = set()
        if full is not None:
            self.values, self.keys, self.bulk = full.values, full.keys, full.bulk

    def key_at(self, path: Path) -> tuple[int, int]:
        """Position of the key of the entry at ``path`` (its value's when not a mapping entry)."""
        if (
            path not in self.keys
            and self.reread is not None
            and any(path[:cut] in self.unplaced for cut in range(len(path)))
        ):
            self._place_all()
        return self.keys.get(path) or self.value_at(path)

    def places(self, path: Path) -> ScalarPlaces | None:
        """Where each character of the string at ``path`` is written; None for a one-line
        plain string (its start plus the offset is exact) or one whose text is not followed."""
        if path in self._places:  # a phrase is placed by check, by load and by its parts
            return self._places[path]
        marks = self.scalars.get(path)
        found = None
        if marks is not None and self.source:
            if self._lines is None:
                self._lines = line_starts(self.source)
            value, style, start, end = marks
            found = scalar_places(self.source, value, style, start, end, self._lines)
        self._places[path] = found
        return found


def json_path(path: Path) -> str:
    """``$.regions.p1[0]`` for ``("regions", "p1", 0)`` (:func:`tlmpc.io.json_places.json_path`:
    a key that is no identifier is written ``["..."]``)."""
    return json_places.json_path(*path)


def _mark(node: Any) -> tuple[int, int]:
    return node.start_mark.line + 1, node.start_mark.column + 1


#: A plain scalar YAML 1.1 reads as text although it looks like a number (``1e-6``,
#: ``1.5e3``: PyYAML's floats need a dot and a signed exponent).
#: The code of a plain scalar YAML 1.1 reads as text although it looks like a number; the
#: mission loader keeps it only where the schema refuses the text.
NUMBER_LIKE_TEXT = "Y010"
_NUMBER_LIKE = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)")
#: Plain numbers YAML 1.1 reads in another base than the decimal one YAML 1.2, JSON and
#: Python read: a leading zero is octal (``010`` is 8), a colon is base 60 (``1:30`` is 90).
_OCTAL = re.compile(r"[-+]?0[0-7_]+")
_NUMBER_TAGS = frozenset(("tag:yaml.org,2002:int", "tag:yaml.org,2002:float"))
#: The tags a mapping or list may carry: the ones it has anyway (``!`` is "no tag").
_COLLECTION_TAGS = frozenset(("!", "tag:yaml.org,2002:map", "tag:yaml.org,2002:seq"))
_TAG_HINT = "a mission needs no YAML tags (!!float, !!set, !!python/...): write the plain value"


def _other_base(text: str, value: float) -> tuple[str, str] | None:
    """The message and hint for a plain number YAML 1.1 read as ``value`` from ``text`` in
    another base than decimal, or None for a decimal (or hexadecimal, or binary) number."""
    if ":" in text:
        return (
            f"{text!r} is the base-60 number {value} in YAML 1.1 (YAML 1.2 and JSON read it "
            "as text)",
            f"write the number in decimal ({value} if that is meant), or quote the text ('{text}')",
        )
    if _OCTAL.fullmatch(text):
        digits = text.replace("_", "")
        decimal = int(digits, 10)
        if decimal != value:
            return (
                f"{text!r} is the octal number {value} in YAML 1.1, not {decimal}",
                f"write {decimal} without the leading zero ({value} if the octal number is "
                f"meant), or quote the text ('{text}')",
            )
    return None


def _json_number(text: str) -> float:
    """A JSON number without a decimal point but with an exponent (``1e-9``, ``2E3``), as
    JSON reads it: a float (``json.loads("1e3")`` is ``1000.0``)."""
    return float(text)


#: Plain numbers that YAML 1.1 reads exactly as Python does (no octal, no ``_``, no
#: sexagesimal, at most 15 digits so they are finite and within the integer limit).
_FAST_INT = re.compile(r"-?(?:0|[1-9][0-9]{0,14})")
_FAST_FLOAT = re.compile(r"[-+]?[0-9]{1,15}\.[0-9]{0,17}")


class _Frame:
    """An open mapping or sequence while the event stream is read."""

    __slots__ = ("anchor", "container", "key", "path", "seen", "shallow", "size", "unplaced")

    def __init__(self, container: Any, path: Path, anchor: str | None) -> None:
        self.container = container
        self.path = path
        self.shallow = len(path) < MAX_DEPTH  # an item's path is within the depth limit
        self.unplaced = False  # a number in it was read without recording its position
        self.anchor = anchor
        self.key: Any = _NO_KEY  # a mapping's pending key (text) or a bad-key marker
        self.seen: dict[str, tuple[int, int] | None] = {}  # None: read without a position
        self.size = 1  # nodes in this subtree, aliases expanded


_NO_KEY = object()
_BAD_KEY = object()


class _TooBig(Exception):
    """Stop reading: the problem that stopped it is recorded."""


class _PlaceEverything(Exception):
    """Stop a lazy reading: a diagnostic needs a position it did not record; read again."""


class _Converter:
    """Plain data and positions from PyYAML's event stream, iteratively.

    Reading events instead of composing PyYAML's node graph avoids the composer's
    recursion (libyaml's composer crashes the interpreter on documents nested ~25,000 deep)
    and lets alias expansion be counted as it happens: an alias adds the size of its anchor
    without copying it, so a "billion laughs" stops after MAX_NODES at the cost of a few
    additions.  Aliased data is shared, never copied; positions inside it are the alias's.
    """

    def __init__(
        self, file: str, lists: dict[str, BulkList] | None = None, *, lazy: bool = False
    ) -> None:
        self.file = file
        #: Record no position for plain numbers in lists (see PositionedDocument.reread).
        self.lazy = lazy
        #: Lists cut out of the text (see tlmpc.mission.bulk) by placeholder, until met.
        self.lists = dict(lists or {})
        #: A placeholder was met where a whole list could not be: read the original text.
        self.mismatch = False
        self.doc = PositionedDocument(data=None)
        self.problems: list[Diagnostic] = []
        self.count = 0
        self.constructor = yaml.SafeLoader("")
        self.resolver = yaml.resolver.Resolver()
        self.anchors: dict[str, tuple[Any, int]] = {}
        #: A ``.json`` file's plain ``1e-9`` is a JSON number (YAML 1.1 would read text).
        self.json_numbers = file.lower().endswith(".json")

    def problem(
        self, code: str, message: str, at: Any, path: Path | None = None, **kw: Any
    ) -> None:
        line, col = _mark(at)
        self.problems.append(
            error(
                code,
                message,
                file=self.file,
                line=line,
                col=col,
                path=None if path is None else json_path(path),
                **kw,
            )
        )

    def scalar(self, event: Any, path: Path) -> Any:
        tag = event.tag
        if tag is None or tag == "!":
            tag = self.resolver.resolve(yaml.ScalarNode, event.value, event.implicit)  # type: ignore[no-untyped-call]
        if tag == "tag:yaml.org,2002:str":
            if not event.style and _NUMBER_LIKE.fullmatch(event.value):
                if self.json_numbers:
                    return _json_number(event.value)
                self.problem(
                    NUMBER_LIKE_TEXT,
                    f"{event.value!r} is text in YAML 1.1, not a number",
                    event,
                    path,
                    hint=f"write the exponent's sign and a decimal point, e.g. "
                    f"{_as_yaml_float(event.value)}",
                )
            return event.value
        node = yaml.ScalarNode(tag, event.value, event.start_mark, event.end_mark, event.style)
        try:
            value = self.constructor.construct_object(node, deep=True)
        except (yaml.YAMLError, ValueError, OverflowError) as exc:
            # a constructor's problem alone: its mark (the value's place) is the diagnostic's
            reason = getattr(exc, "problem", None) or str(exc)
            self.problem(
                "Y004",
                f"cannot read the value {event.value!r}: {reason}",
                event,
                path,
                hint=_TAG_HINT,
            )
            return None
        if event.tag is None and not event.style and tag in _NUMBER_TAGS:
            other_base = _other_base(event.value, value)
            if other_base is not None:
                self.problem("Y011", other_base[0], event, path, hint=other_base[1])
                return None
        if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**15:
            value = float("inf") if value > 0 else float("-inf")
        if isinstance(value, float) and not math.isfinite(value):
            self.problem(
                "Y005",
                f"the number {event.value!r} is not finite",
                event,
                path,
                hint="use a finite number (no .nan, .inf, or values too large for a float)",
            )
        return value

    def convert(self, events: Iterator[Any]) -> bool:
        """Read one document; False when the stream holds no document."""
        stack: list[_Frame] = []
        documents = 0
        values = self.doc.values
        # The loop runs once per YAML value (a million on large maps): names bound locally.
        scalar_event = yaml.ScalarEvent
        mapping_start, sequence_start = yaml.MappingStartEvent, yaml.SequenceStartEvent
        ends = (yaml.MappingEndEvent, yaml.SequenceEndEvent)
        fast_float = _FAST_FLOAT.fullmatch
        fast_int = _FAST_INT.fullmatch
        lazy = self.lazy
        for event in events:
            kind = type(event)
            if (
                (kind is mapping_start or kind is sequence_start)
                and event.tag is not None
                and event.tag not in _COLLECTION_TAGS
            ):
                self.problem(
                    "Y004",
                    f"cannot read the {'mapping' if kind is mapping_start else 'list'} tagged "
                    f"{event.tag.replace('tag:yaml.org,2002:', '!!')!r}",
                    event,
                    hint=_TAG_HINT,
                )
            if (kind is mapping_start or kind is sequence_start) and stack:
                # A container as a list item or as the value of a named key: as below.
                frame = stack[-1]
                holder = frame.container
                if type(holder) is list:
                    path: Path | None = (*frame.path, len(holder))
                elif type(holder) is dict and type(frame.key) is str:
                    path = (*frame.path, frame.key)
                else:
                    path = None
                if path is not None and len(path) <= MAX_DEPTH and self.count < MAX_NODES:
                    self.count += 1
                    if lazy and len(path) > 1:
                        frame.unplaced = True  # a container below the top level: no position
                    else:
                        mark = event.start_mark
                        values[path] = (mark.line + 1, mark.column + 1)
                    opened: Any = {} if kind is mapping_start else []
                    if type(holder) is list:
                        holder.append(opened)
                    else:
                        holder[frame.key] = opened
                        frame.key = _NO_KEY
                    frame = _Frame(opened, path, event.anchor)
                    stack.append(frame)
                    if kind is mapping_start or not frame.shallow:
                        continue
                    # A list: its plain numbers are read right here, as the number branch
                    # below would read them one event at a time; the event after them (the
                    # list's end, mostly) falls through to the branches below.
                    room = MAX_NODES - self.count
                    for event in events:  # the same stream, read on
                        if (
                            type(event) is not scalar_event
                            or event.style
                            or event.tag is not None
                            or event.anchor is not None
                            or not room
                        ):
                            break
                        text = event.value
                        if fast_float(text):
                            opened.append(float(text))
                        elif fast_int(text):
                            opened.append(int(text))
                        else:
                            break
                        room -= 1
                        if not lazy:
                            values[(*path, len(opened) - 1)] = _mark(event)
                    read = len(opened)
                    if read:
                        self.count += read
                        frame.size += read
                        frame.unplaced = lazy
                    kind = type(event)
            if kind in ends:  # the parser balances them: a container is open
                frame = stack.pop()
                if frame.unplaced:
                    self.doc.unplaced.add(frame.path)
                if frame.anchor is not None:
                    self.anchors[frame.anchor] = (frame.container, frame.size)
                if stack:
                    stack[-1].size += frame.size
                continue
            if kind is scalar_event and stack:
                frame = stack[-1]
                items = frame.container
                if type(items) is dict and frame.key is _NO_KEY:  # a key: as below, directly
                    key = str(event.value)
                    if key in frame.seen or key == "<<" or (self.lists and STEM in key):
                        # a duplicate, a merge key, or a placeholder as a key
                        self._key(frame, event)
                    elif lazy and frame.path:  # below the top level: no position (see _key)
                        frame.seen[key] = None
                        frame.unplaced = True
                        frame.key = key
                    else:  # what _key does with a new plain key
                        mark = event.start_mark
                        position = (mark.line + 1, mark.column + 1)
                        frame.seen[key] = position
                        self.doc.keys[(*frame.path, key)] = position
                        frame.key = key
                    continue
                # fast path: a number in a list
                if (
                    type(items) is list
                    and not event.style
                    and event.tag is None
                    and event.anchor is None
                    and frame.shallow
                    and self.count < MAX_NODES
                ):
                    text = event.value
                    number: float | int | None = None
                    if fast_float(text):
                        number = float(text)
                    elif fast_int(text):
                        number = int(text)
                    if number is not None:
                        self.count += 1
                        if lazy:
                            frame.unplaced = True
                        else:
                            mark = event.start_mark
                            values[(*frame.path, len(items))] = (mark.line + 1, mark.column + 1)
                        items.append(number)
                        frame.size += 1
                        continue
            if isinstance(event, yaml.DocumentStartEvent):
                documents += 1
                if documents > 1:
                    self.problem(
                        "Y001",
                        "YAML syntax error: expected a single document",
                        event,
                        hint="a mission file holds one document: remove this `---` and what "
                        "follows it, or move it to a file of its own",
                    )
                    raise _TooBig
                continue
            if isinstance(
                event, (yaml.StreamStartEvent, yaml.StreamEndEvent, yaml.DocumentEndEvent)
            ):
                continue
            parent = stack[-1] if stack else None
            path = self._child_path(parent)
            if path is None:  # a mapping key
                assert parent is not None
                self._key(parent, event)
                if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
                    stack.append(_Frame(None, parent.path, None))  # skipped: not a name
                continue
            if isinstance(event, yaml.AliasEvent):
                if event.anchor not in self.anchors:
                    self.problem(
                        "Y001",
                        f"YAML syntax error: undefined alias {event.anchor!r}",
                        event,
                        hint=f"an alias *{event.anchor} names an anchor &{event.anchor} given "
                        "earlier in the file; define it first or write the value out",
                    )
                    raise _TooBig
                value, size = self.anchors[event.anchor]
                self._count(size, event)
                self.doc.values[path] = _mark(event)
                self._store(parent, value, size)
                continue
            self._count(1, event)
            if parent is not None and parent.container is None:  # inside a skipped key
                if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
                    stack.append(_Frame(None, parent.path, None))
                continue
            if len(path) > MAX_DEPTH:
                self.problem(
                    "Y003",
                    f"the document is nested more than {MAX_DEPTH} levels deep",
                    event,
                    hint="no mission nests deeper than a few levels: a point is [x, y], a "
                    "polygon a list of points; look for unbalanced brackets",
                )
                raise _TooBig
            self.doc.values[path] = _mark(event)
            if self.lists and isinstance(event, yaml.ScalarEvent) and STEM in event.value:
                self._bulk(parent, event, path)
                continue
            if isinstance(event, yaml.ScalarEvent):
                self.doc.quoted[path] = event.style in ("'", '"')
                self.doc.block[path] = event.style in ("|", ">")
                value = self.scalar(event, path)
                start, end = event.start_mark, event.end_mark
                if (
                    isinstance(value, str)
                    and start is not None
                    and end is not None
                    and (event.style or start.line != end.line)
                ):
                    self.doc.scalars[path] = (
                        value,
                        event.style,
                        (start.line, start.column),
                        (end.line, end.column),
                    )
                if event.anchor is not None:
                    self.anchors[event.anchor] = (value, 1)
                self._store(parent, value, 1)
            else:
                container: Any = {} if isinstance(event, yaml.MappingStartEvent) else []
                self._store(parent, container, 0)
                stack.append(_Frame(container, path, event.anchor))
        return documents > 0

    def _count(self, size: int, event: Any) -> None:
        self.count += size
        if self.count > MAX_NODES:
            self.problem(
                "Y003",
                f"the document is too large (more than {MAX_NODES:,} values, aliases expanded)",
                event,
                hint="missions do not need YAML aliases; write long point lists as one flow "
                "list of plain decimals, [[x, y], ...] (read in bulk, not value by value)",
            )
            raise _TooBig

    def _child_path(self, parent: _Frame | None) -> Path | None:
        """The path of the next value in ``parent``; None when the next event is a key."""
        if parent is None:
            return ()
        if isinstance(parent.container, list):
            return (*parent.path, len(parent.container))
        if parent.key is _NO_KEY:
            return None
        if parent.key is _BAD_KEY:
            return (*parent.path, "?")
        return (*parent.path, parent.key)

    def _key(self, parent: _Frame, event: Any) -> None:
        if parent.container is None:
            parent.key = _BAD_KEY
            return
        if not isinstance(event, yaml.ScalarEvent):
            self.problem(
                "Y006",
                "mapping keys must be plain names",
                event,
                parent.path,
                hint="write the key as a name (`home:`), not a list, a mapping or an alias",
            )
            parent.key = _BAD_KEY
            return
        key = str(event.value)
        if key == "<<" and not event.style and event.tag is None:
            self.problem(
                "Y006",
                "YAML merge keys (`<<`) are not read in a mission",
                event,
                parent.path,
                hint="write the keys out (an alias `*name` may still stand for a whole value)",
            )
            parent.key = _BAD_KEY
            return
        if self.lists and STEM in key:
            self.mismatch = True
        if key in parent.seen:
            first = parent.seen[key]
            if first is None:  # read lazily: the hint needs where it was first given
                raise _PlaceEverything
            self.problem(
                "Y002",
                f"duplicate key {key!r}",
                event,
                (*parent.path, key),
                hint=f"it was already given at line {first[0]}; YAML would "
                "silently keep only the last one",
            )
            parent.key = _BAD_KEY
            return
        parent.seen[key] = _mark(event)
        self.doc.keys[(*parent.path, key)] = _mark(event)
        parent.key = key

    def _bulk(self, parent: _Frame | None, event: Any, path: Path) -> None:
        """Put the list cut out for the placeholder ``event`` in its place."""
        bulk = self.lists.pop(event.value, None)
        if (
            bulk is None
            or event.style
            or event.tag is not None
            or len(path) + bulk.depth > MAX_DEPTH
        ):
            self.mismatch = True  # not a whole list in a value's place: read the original
            self._store(parent, None, 1)
            return
        # The list's "[" (the event starts at an anchor, when there is one).
        bulk.line = event.end_mark.line + 1
        bulk.col = event.end_mark.column + 1 - len(bulk.placeholder)
        self.doc.bulk[path] = bulk
        self.doc.quoted[path] = self.doc.block[path] = False
        if event.anchor is not None:
            self.anchors[event.anchor] = (bulk.value, bulk.values)
        self._store(parent, bulk.value, bulk.values)

    def _store(self, parent: _Frame | None, value: Any, size: int) -> None:
        if parent is None:
            self.doc.data = value
            return
        parent.size += size
        if isinstance(parent.container, list):
            parent.container.append(value)
        elif isinstance(parent.container, dict):
            if parent.key is not _BAD_KEY:
                parent.container[parent.key] = value
            parent.key = _NO_KEY
        else:
            parent.key = _NO_KEY


def _as_yaml_float(text: str) -> str:
    mantissa, _, exponent = text.lower().partition("e")
    if "." not in mantissa:
        mantissa += ".0"
    if exponent[:1] not in ("+", "-"):
        exponent = "+" + exponent
    return f"{mantissa}e{exponent}"


#: A JSON string literal, and a UTF-16 surrogate pair escaped in one (``\ud83d\ude00``).
_JSON_STRING = re.compile(r'"(?:[^"\\\n]|\\.)*"')
_SURROGATE_PAIR = re.compile(r"\\u([dD][89abAB][0-9a-fA-F]{2})\\u([dD][c-fC-F][0-9a-fA-F]{2})")
#: Inside a string: a surrogate pair escape, or any other escape (skipped whole, so that the
#: ``\\`` of ``"\\ud83d"`` is not read as the start of one).
_STRING_ESCAPE = re.compile(_SURROGATE_PAIR.pattern + r"|\\.")


def json_surrogate_pairs(text: str) -> str:
    r"""``text`` with each surrogate pair escape in a JSON string written as the one YAML
    escape of its character (``\U0001F600``), padded after the string to keep columns.

    JSON writers (Python's ``json.dumps`` by default) escape a character beyond U+FFFF as two
    UTF-16 escapes; libyaml refuses each half of the pair.  The padding is two spaces after
    the string's closing quote per pair, where JSON and YAML flow both allow white space, so
    everything after it on the line keeps its column."""
    if not _SURROGATE_PAIR.search(text):
        return text

    def one_string(literal: re.Match[str]) -> str:
        pairs = 0

        def one_escape(escape: re.Match[str]) -> str:
            nonlocal pairs
            if escape.group(1) is None:
                return escape.group()
            pairs += 1
            high, low = int(escape.group(1), 16), int(escape.group(2), 16)
            return f"\\U{0x10000 + ((high - 0xD800) << 10) + (low - 0xDC00):08X}"

        rewritten = _STRING_ESCAPE.sub(one_escape, literal.group())
        return rewritten + "  " * pairs

    return _JSON_STRING.sub(one_string, text)


def load_positioned(
    text: str, file: str, *, lazy: bool = False
) -> tuple[PositionedDocument | None, list[Diagnostic]]:
    """Parse YAML ``text``; return the data with positions, or None and the diagnostics.

    ``lazy``: the plain numbers of lists get no position while reading (a tenth of the time
    on large maps); the first question about one reads the text again with every position.
    A ``.json`` file's surrogate pair escapes read as JSON reads them
    (:func:`json_surrogate_pairs`).
    """
    foreign = foreign_line_break(text, "Y001", file)
    if foreign is not None:
        return None, [foreign]
    if file.lower().endswith(".json"):
        text = json_surrogate_pairs(text)
    doc, problems = _load_positioned(text, file, lazy)
    if doc is not None:
        doc.source = text
    if doc is not None and doc.unplaced:
        doc.reread = lambda: _load_positioned(text, file, False)[0]
    return doc, problems


def _load_positioned(
    text: str, file: str, lazy: bool
) -> tuple[PositionedDocument | None, list[Diagnostic]]:
    try:
        return _read_positioned(text, file, lazy)
    except _PlaceEverything:
        return _read_positioned(text, file, False)


def _read_positioned(
    text: str, file: str, lazy: bool
) -> tuple[PositionedDocument | None, list[Diagnostic]]:
    cut, lists = cut_out(text)
    if lists:
        converter = _Converter(file, lists, lazy=lazy)
        outcome = _convert(converter, cut)
        # The answer stands when every placeholder met was a whole list in a value's place:
        # the text up to where reading stopped then means the same as the original.
        if not converter.mismatch:
            if isinstance(outcome, yaml.YAMLError):
                mark = getattr(outcome, "problem_mark", None)
                if (
                    mark is not None
                    and not _unmet_before(converter, cut, mark)
                    and not _ends_on_line(converter, mark)
                ):
                    return _result(converter, outcome, file)
            elif outcome is None or not converter.lists:  # a limit stopped it, or all met
                return _result(converter, outcome, file)
    converter = _Converter(file, lazy=lazy)
    return _result(converter, _convert(converter, text), file, text=text)


def _unmet_before(converter: _Converter, cut: str, mark: Any) -> bool:
    """Whether a list not yet met starts on or before the line of ``mark``."""
    for bulk in converter.lists.values():
        start = cut.find(bulk.placeholder)
        if cut.count("\n", 0, start) <= mark.line:
            return True
    return False


def _ends_on_line(converter: _Converter, mark: Any) -> bool:
    """Whether a list read in bulk ends on the line of ``mark``: the error may be about what
    follows the list (a multi-line list used as a key, say), which the stand-in does not
    reproduce word for word."""
    return any(
        bulk.line + bulk.text.count("\n") == mark.line + 1 for bulk in converter.doc.bulk.values()
    )


def _convert(converter: _Converter, text: str) -> bool | yaml.YAMLError | None:
    """Whether ``text`` held a document; None when a limit stopped reading; or the error."""
    try:
        # The loader's events without yaml.parse's generator around them (a tenth of the
        # reading time); get_event gives None after the stream's end.
        loader = _LOADER(text)
        try:
            return converter.convert(iter(loader.get_event, None))
        finally:
            loader.dispose()
    except _TooBig:
        return None
    except yaml.YAMLError as exc:
        return _limit_before(converter, text, exc)
    except (ValueError, OverflowError):
        # PyYAML's pure-Python scanner reads an escape past U+10FFFF (``"\U0011FFFF"``) with
        # chr(), which raises; libyaml refuses it as a scanner error at the escape
        return yaml.scanner.ScannerError(
            "while parsing a quoted scalar",
            None,
            "found invalid Unicode character escape code",
            loader.get_mark(),
        )


def _limit_before(converter: _Converter, text: str, exc: yaml.YAMLError) -> yaml.YAMLError | None:
    """``exc``, unless one of our own limits is met in the text before it (then None).

    A parser scans ahead of the events it has handed over (a flow collection may turn out to
    be a mapping key), and libyaml refuses nesting past its own depth while doing so: 1,000
    ``[`` on one line fail there before this reader has seen the 65th.  Which limit a mission
    meets must not depend on the parser's build or version, so the text up to the failure's
    line is read again with PyYAML's pure-Python parser, which hands over every event as it
    goes and has no limit of its own; when our reader stops that reading (too deep, too
    large), that is the answer, else the parser's error stands.
    """
    mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
    if mark is None or _LOADER is yaml.SafeLoader:
        return exc  # no position to read up to, or already read by the pure-Python parser
    end = -1
    for _ in range(mark.line + 1):
        end = text.find("\n", end + 1)
        if end < 0:
            end = len(text)
            break
    probe = _Converter(converter.file, converter.lists)
    loader = yaml.SafeLoader(text[:end])
    try:
        probe.convert(iter(loader.get_event, None))
    except _TooBig:
        converter.problems.extend(probe.problems)
        return None
    except (yaml.YAMLError, ValueError, OverflowError):
        pass  # the text stops inside a value, or an escape past U+10FFFF: the error stands
    finally:
        loader.dispose()
    return exc


def _result(
    converter: _Converter, outcome: bool | yaml.YAMLError | None, file: str, *, text: str = ""
) -> tuple[PositionedDocument | None, list[Diagnostic]]:
    """The document or the problems of one reading; ``text`` is what was read, to place a
    character YAML refuses (only the reading of the original text can meet one: the bulk
    reading's answers stand only at a parser's mark)."""
    if outcome is None:
        return None, converter.problems
    if isinstance(outcome, yaml.YAMLError):
        return None, [yaml_error(outcome, "Y001", file, text)]
    if not outcome or (converter.doc.data is None and not converter.problems):
        return None, [
            error(
                "Y007",
                "the file is empty",
                file=file,
                line=1,
                col=1,
                hint="a mission starts with `version: 1`",
            )
        ]
    return converter.doc, converter.problems
