"""Load a mission file: YAML → schema → geometry → task, every problem with its position.

All problems of a file are reported in one run, best first.  Later checks are skipped only
where they would be meaningless (the geometry of a shape that failed the schema, say).
"""

from __future__ import annotations

import dataclasses
import difflib
import gc
import math
import re
from collections.abc import Callable, Mapping
from itertools import chain
from pathlib import Path as FilePath
from typing import TYPE_CHECKING, Any

from tlmpc.base.depth import NESTING_LIMIT
from tlmpc.base.errors import Diagnostic, InvalidInputError, UsageError, best_first, error
from tlmpc.io.scalar_places import ScalarPlaces
from tlmpc.io.schema_check import MISSION_COORDINATE_LIMIT, is_valid, load_schema
from tlmpc.ltl.ast import Formula, Prop, bounded_operators, conjoin
from tlmpc.ltl.keywords import KEYWORDS
from tlmpc.ltl.transform import normal_form_refusal, normal_form_size, substitute
from tlmpc.mission.geometry import check_layout, check_shape
from tlmpc.mission.model import (
    MOTION_NAMES,
    Component,
    Mission,
    Options,
    Polygon,
    Reactive,
    Region,
    Robot,
    Sensor,
    TaskPart,
    Workspace,
)
from tlmpc.mission.parts import group_expansion
from tlmpc.mission.shapes import CheckedShape, shapely_polygon
from tlmpc.mission.yamlpos import (
    NUMBER_LIKE_TEXT,
    Path,
    PositionedDocument,
    json_path,
    load_positioned,
)
from tlmpc.tasks.compiler import NameKinds, compile_phrase, compile_phrases

if TYPE_CHECKING:
    from jsonschema.exceptions import ValidationError

#: Files larger than this are refused while reading, before parsing (Example 8, a thousand
#: rooms, is 52 KB; a 10^6-vertex boundary 24 to 45 MB, depending on the digits written).
MAX_BYTES = 256 * 1024 * 1024

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")

#: Further pieces of free space (``workspace.components``): each boundary with its holes.
Pieces = list[tuple[CheckedShape, list[CheckedShape]]]


#: The types of the numbers YAML reads (``bool`` is an ``int`` but no number here).
_NUMBER_TYPES = frozenset((int, float))
_WITHIN_LIMIT = MISSION_COORDINATE_LIMIT.__ge__


def _is_name(value: Any) -> bool:
    """The schema's rule for a name: an identifier that is not an LTL keyword."""
    return isinstance(value, str) and bool(_NAME.match(value)) and value not in KEYWORDS


def _number(value: Any) -> bool:
    return (
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and abs(value) <= MISSION_COORDINATE_LIMIT
    )


def _plain_shape(value: Any) -> bool:
    """A quick structural check equivalent to the schema's `shape` for valid shapes."""
    if isinstance(value, dict):
        rect = value.get("rect")
        # _number of each value, at C speed (a map may have 10^4 rect rooms)
        return (
            len(value) == 1
            and isinstance(rect, list)
            and len(rect) == 4
            and not set(map(type, rect)) - _NUMBER_TYPES
            and all(map(_WITHIN_LIMIT, map(abs, rect)))  # NaN is no number either
        )
    if not isinstance(value, list) or len(value) < 3:
        return False
    # Type by type at C speed (a boundary may have a million points): every point a list of
    # two ints or floats (not bools), each within the coordinate limit.
    if set(map(type, value)) != {list} or set(map(len, value)) != {2}:
        return False
    coordinates = list(chain.from_iterable(value))
    if not set(map(type, coordinates)) <= {int, float}:
        return False
    return all(map(_WITHIN_LIMIT, map(abs, coordinates)))  # NaN is no coordinate either


_STAND_IN = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]


def _small_component(component: Any, path: Path, bad: list[Path]) -> Any:
    """The workspace, or one of its components, with its boundary and holes replaced by small
    stand-ins (see ``_small``)."""
    if not isinstance(component, dict):
        return component
    small = dict(component)
    if "boundary" in small:
        small["boundary"] = _small(small["boundary"], (*path, "boundary"), bad)
    holes = small.get("holes")
    if isinstance(holes, list):
        small["holes"] = [_small(h, (*path, "holes", i), bad) for i, h in enumerate(holes)]
    return small


def _number_like_where_refused(
    number_like: list[Diagnostic], schema: list[Diagnostic]
) -> list[Diagnostic]:
    """The schema's diagnostics, each at a value YAML 1.1 read as text although it looks like a
    number (``1e-6``) replaced by that finding, which says how to write the number.  Where
    the schema takes the text (a name ``1e3``) it is no problem at all."""
    at = {p.path: p for p in number_like}
    found = [at.get(p.path, p) for p in schema]
    return list(dict.fromkeys(found))  # one finding per value, in the schema's order


class _Refusals:
    """The values the schema refused, by path: later checks skip each of them, what it
    contains, and (for a whole-section check) what contains it."""

    def __init__(self, paths: list[Path]) -> None:
        self._refused = set(paths)
        # every path on the way to a refused value: a container with a refused part
        self._touched = {path[:depth] for path in paths for depth in range(len(path) + 1)}

    def readable(self, path: Path) -> bool:
        """Neither the value at ``path`` nor one of its containers was refused: its parts
        that passed may be read one by one."""
        return not any(path[:depth] in self._refused for depth in range(len(path) + 1))

    def clean(self, path: Path) -> bool:
        """The value at ``path`` passed the schema whole: nothing in it or around it refused."""
        return path not in self._touched and self.readable(path)


def _refused_paths(err: ValidationError) -> list[Path]:
    """The paths of the values a schema problem refuses: the missing or unknown key, or the
    badly named one, rather than the mapping that holds it; both entries of the task for a
    mission without one."""
    path: Path = tuple(err.absolute_path)
    instance = err.instance
    if err.validator == "required" and isinstance(instance, dict):
        required: Any = err.validator_value
        return [(*path, key) for key in required if key not in instance]
    if err.validator == "additionalProperties" and isinstance(instance, dict):
        allowed = err.schema.get("properties", {}) if isinstance(err.schema, dict) else {}
        return [(*path, key) for key in instance if key not in allowed]
    if "propertyNames" in err.absolute_schema_path and isinstance(instance, str):
        return [(*path, instance)]
    if err.validator == "anyOf" and not path:
        return [("task",), ("ltl",)]  # S003: neither is there
    return [path]


def _schema_diagnostics(doc: PositionedDocument, file: str) -> tuple[list[Diagnostic], list[Path]]:
    """The schema's problems, and the paths of the values they refuse."""
    data = doc.data
    regions = data.get("regions") if isinstance(data, dict) else None
    if (
        isinstance(regions, dict)
        and len(regions) > 1
        and all(_is_name(k) and _plain_shape(v) for k, v in regions.items())
    ):
        # Maps with thousands of rooms: every region already has the schema's shape, so
        # validate the rest of the document with one representative region (same verdict,
        # a hundred times faster than descending into every region).
        first = next(iter(regions))
        data = {**data, "regions": {first: regions[first]}}
    bad: list[Path] = []
    workspace = data.get("workspace") if isinstance(data, dict) else None
    if isinstance(workspace, dict):
        # A boundary or hole with 10^5 vertices: the schema would descend into every point
        # (a minute); a plain shape has the schema's shape, so validate a small stand-in.
        small = _small_component(workspace, ("workspace",), bad)
        components = small.get("components")
        if isinstance(components, list):
            small["components"] = [
                _small_component(c, ("workspace", "components", i), bad)
                for i, c in enumerate(components)
            ]
        data = {**data, "workspace": small}
    problems = [p for path in bad for p in _point_problem(path, doc, file)]
    if not problems and is_valid(data, "mission"):
        return [], []  # jsonschema (a tenth of a second to import) only words problems
    import jsonschema

    refused = list(bad)
    validator = jsonschema.Draft202012Validator(load_schema("mission"))
    for err in validator.iter_errors(data):
        problems.extend(_describe(err, doc, file))
        refused.extend(_refused_paths(err))
    return problems, refused


#: Point lists longer than this with a bad point are checked point by point, not by the schema.
_LONG = 1000


def _small(shape: Any, path: Path, bad: list[Path]) -> Any:
    """A stand-in for a long point list: three points; a bad point's path goes to ``bad``."""
    if _plain_shape(shape):
        return _STAND_IN
    if not isinstance(shape, list) or len(shape) <= _LONG:
        return shape
    for index, point in enumerate(shape):
        if not (
            isinstance(point, list) and len(point) == 2 and _number(point[0]) and _number(point[1])
        ):
            bad.append((*path, index))  # the first bad point, as the schema reports one
            break
    return _STAND_IN


def _point_problem(path: Path, doc: PositionedDocument, file: str) -> list[Diagnostic]:
    """The schema's verdict on the point at ``path`` alone, described at its place."""
    point: Any = doc.data
    for part in path:
        point = point[part]
    definitions: Any = load_schema("mission")["$defs"]
    schema = {"$ref": "#/$defs/point", "$defs": definitions}
    import jsonschema

    alone = jsonschema.Draft202012Validator(schema)
    return [d for err in alone.iter_errors(point) for d in _describe(err, doc, file, path)]


#: What a JSON type is called in a hint, with an example where one helps.
_TYPE_WORDS = {
    "number": "a number, such as 2.5",
    "integer": "a whole number",
    "string": "text",
    "array": "a list, [...]",
    "object": "a mapping of keys to values",
    "boolean": "true or false",
    "null": "null",
}


def _expected(err: ValidationError) -> str:
    """The hint of a schema problem: what the failed keyword asks for, and what the schema
    says the value is part of (the nearest ``description`` on the way to the keyword)."""
    parts = [_asked(str(err.validator), err.validator_value)]
    description = _nearest_description(list(err.absolute_schema_path))
    parts.append(f"it belongs to: {description}" if description else "see docs/mission-format.md")
    return "; ".join(part for part in parts if part)


#: What a bound keyword of the schema asks for, by keyword.
_BOUNDS = {
    "minItems": "give at least {} items",
    "maxItems": "give at most {} items",
    "minimum": "write a number of at least {}",
    "exclusiveMinimum": "write a number above {}",
    "maximum": "write a number of at most {}",
    "minLength": "write at least {} characters",
    "minProperties": "give at least {} keys",
}


def _asked(keyword: str, wanted: Any) -> str:
    """What the schema keyword ``keyword`` with value ``wanted`` asks for, in words ("" for a
    keyword whose own message says it)."""
    if keyword == "type":
        types = [wanted] if isinstance(wanted, str) else list(wanted)
        return "write " + " or ".join(_TYPE_WORDS.get(t, str(t)) for t in types)
    if keyword == "enum":
        return "write one of: " + ", ".join(str(choice) for choice in wanted)
    if keyword == "const":
        return f"write {wanted}"
    return _BOUNDS.get(keyword, "").format(wanted)


def _nearest_description(schema_path: list[Any]) -> str | None:
    """The last ``description`` below the root met walking the mission schema along
    ``schema_path`` (which jsonschema gives with each ``$ref`` already followed, so the walk
    follows them too)."""
    root: Any = load_schema("mission")
    node: Any = root
    found: str | None = None
    for key in schema_path:
        while isinstance(node, dict):
            if node is not root and isinstance(node.get("description"), str):
                found = node["description"]  # the root's is the whole mission's: no help
            reference = node.get("$ref")
            if key in node or not isinstance(reference, str) or not reference.startswith("#/"):
                break
            node = root
            for part in reference[2:].split("/"):
                node = node.get(part) if isinstance(node, dict) else None
        in_dict = isinstance(node, dict) and key in node
        in_list = isinstance(node, list) and isinstance(key, int) and 0 <= key < len(node)
        if not (in_dict or in_list):
            break
        node = node[key]
    return found


def _describe(
    err: ValidationError, doc: PositionedDocument, file: str, prefix: Path = ()
) -> list[Diagnostic]:
    path: Path = (*prefix, *err.absolute_path)
    if err.validator == "additionalProperties" and isinstance(err.instance, dict):
        schema: Any = err.schema
        allowed = list(schema.get("properties", {}))
        result = []
        for key in err.instance:
            if key in allowed:
                continue
            close = difflib.get_close_matches(str(key), allowed, n=1)
            line, col = doc.key_at((*path, key))
            suggestion = (
                f"did you mean {close[0]!r}?" if close else f"allowed keys: {', '.join(allowed)}"
            )
            result.append(
                error(
                    "S001",
                    f"unknown key {key!r}" + (f" in {json_path(path)}" if path else ""),
                    hint=suggestion,
                    file=file,
                    line=line,
                    col=col,
                    path=json_path((*path, key)),
                )
            )
        return result
    if err.validator == "anyOf" and err.context:
        schema_any: Any = err.schema
        if list(schema_any.get("anyOf", [{}])[0]) == ["required"]:
            line, col = doc.value_at(path)
            return [
                error(
                    "S003",
                    "the mission has no task: give `task` phrases, `ltl`, or both",
                    hint="for example  task: [visit goal]",
                    file=file,
                    line=line,
                    col=col,
                    path=json_path(path),
                )
            ]
        from jsonschema.exceptions import best_match

        # The shape's kind is the value's own (a mapping with `rect`, or a list of points):
        # the problems of that kind's branch say what is wrong with it; a value of neither
        # kind ({polygon: [...]}, a number) is told what a shape is.
        branches: list[Any] = schema_any.get("anyOf", [])
        kind = "rect" if isinstance(err.instance, dict) and "rect" in err.instance else None
        if isinstance(err.instance, list):
            kind = "pointList"
        own = [
            e
            for e in err.context
            if kind is not None
            and str(branches[int(e.relative_schema_path[0])].get("$ref", "")).endswith(kind)
        ]
        deepest = best_match(own) if own else err
        if deepest is not None and deepest is not err:
            return _describe(deepest, doc, file, prefix)
        line, col = doc.value_at(path)
        return [
            error(
                "S004",
                f"{json_path(path)} is not a shape",
                hint="a shape is a list of [x, y] points or {rect: [xmin, ymin, xmax, ymax]}",
                file=file,
                line=line,
                col=col,
                path=json_path(path),
            )
        ]
    if err.validator == "required":
        line, col = doc.value_at(path)
        return [
            error(
                "S002",
                err.message.replace("is a required property", "is missing (required)"),
                hint="see docs/mission-format.md for the keys",
                file=file,
                line=line,
                col=col,
                path=json_path(path),
            )
        ]
    if "propertyNames" in err.absolute_schema_path and isinstance(err.instance, str):
        path = (*path, err.instance)  # point at the offending name itself
        line, col = doc.key_at(path)
    else:
        line, col = doc.value_at(path)
    code = {
        "type": "S005",
        "const": "S006",
        "enum": "S007",
        "pattern": "S008",
        "not": "S008",
        "minItems": "S009",
        "maxItems": "S009",
        "minimum": "S010",
        "maximum": "S010",
        "exclusiveMinimum": "S010",
        "minProperties": "S009",
        "minLength": "S009",
    }.get(str(err.validator), "S000")
    message = err.message
    hint: str | None = _expected(err)
    if err.validator == "const" and path == ("version",):
        message = f"unsupported mission format version {err.instance!r}"
        hint = "this tlmpc reads `version: 1`"
    elif _text_read_as_other(err):
        message, hint = _yaml11_word(err.instance, doc, line, col)
    elif err.validator in ("pattern", "not"):
        message = f"{err.instance!r} is not a valid name"
        hint = (
            "names are identifiers (letters, digits, _) and not LTL keywords "
            "(F G X N U R W M V true false)"
        )
    return [
        error(
            code,
            f"{json_path(path)}: {message}",
            hint=hint,
            file=file,
            line=line,
            col=col,
            path=json_path(path),
        )
    ]


#: The plain words YAML 1.1 reads as booleans or null (PyYAML's resolver), not as text.
_YAML11_WORDS = frozenset(
    f(word)
    for word in ("yes", "no", "on", "off", "true", "false", "null")
    for f in (str.lower, str.title, str.upper)
) | {"~"}


def _text_read_as_other(err: ValidationError) -> bool:
    """A value the schema wants as text (a name, a phrase) that YAML read as a boolean or null."""
    if err.validator != "type" or not (err.instance is None or isinstance(err.instance, bool)):
        return False
    wanted: Any = err.validator_value
    return "string" in ([wanted] if isinstance(wanted, str) else list(wanted))


def _yaml11_word(value: Any, doc: PositionedDocument, line: int, col: int) -> tuple[str, str]:
    """The message and hint of a word such as ``yes`` written where text is wanted: YAML 1.1
    reads it as a boolean (or null), so a name ``yes`` must be quoted."""
    reading = "null" if value is None else f"the boolean {str(value).lower()}"
    lines = doc.source.splitlines()
    written = (
        re.match(r"[^\s,\[\]{}#]+", lines[line - 1][col - 1 :]) if 0 < line <= len(lines) else None
    )
    if written is None or written.group(0) not in _YAML11_WORDS:
        if value is None:
            return "an empty value (null) is not text", "write text, e.g. a name"
        return f"{reading} is not text", "write text; quote a word to make it text"
    word = written.group(0)
    return (
        f"{word} is read by YAML as {reading}, not as text",
        f"quote it: '{word}' (YAML 1.1 reads yes, no, on, off, true, false as booleans and "
        "null, ~ as null)",
    )


def _ltl_position(doc: PositionedDocument, path: Path) -> tuple[int, int]:
    """Where the text of the string at ``path`` starts (its first character)."""
    places = doc.places(path)
    if places is not None:
        return places.at_offset(0)
    line, col = doc.value_at(path)
    if doc.quoted.get(path):
        col += 1
    if doc.block.get(path):
        line, col = line + 1, 1  # block scalars start on the next line; indentation is lost
    return line, col


def _check_task(
    data: Mapping[str, Any],
    doc: PositionedDocument,
    file: str,
    names: set[str],
    groups: Mapping[str, list[str]],
    kinds: NameKinds | None = None,
) -> tuple[Formula | None, list[Diagnostic]]:
    problems: list[Diagnostic] = []
    parts: list[Formula] = []
    # without sensors or actions too: a region is no condition (T020)
    known = kinds or NameKinds(regions=frozenset(names), groups=frozenset(groups))
    phrases = data.get("task")
    if isinstance(phrases, list) and phrases and all(isinstance(p, str) for p in phrases):
        positions = [_ltl_position(doc, ("task", i)) for i in range(len(phrases))]
        try:
            parts.append(
                compile_phrases(
                    phrases,
                    groups=groups,
                    file=file,
                    positions=positions,
                    places=[doc.places(("task", i)) for i in range(len(phrases))],
                    kinds=known,
                )
            )
        except InvalidInputError as exc:
            problems.extend(exc.diagnostics)
    ltl = data.get("ltl")
    if isinstance(ltl, str) and not ltl.strip():
        line, col = doc.value_at(("ltl",))
        problems.append(
            error(
                "S020",
                "`ltl` is blank",
                hint="write a formula, e.g.  ltl: F goal  (or leave the key out and use `task`)",
                file=file,
                line=line,
                col=col,
                path="$.ltl",
            )
        )
    if isinstance(ltl, str) and ltl.strip():
        from tlmpc.ltl.parser import parse_ltl  # lark: only for missions with `ltl`

        line, col = _ltl_position(doc, ("ltl",))
        place = doc.places(("ltl",))
        try:
            parts.append(parse_ltl(ltl, file=file, line=line, col=col, place=place))
        except InvalidInputError as exc:
            problems.extend(exc.diagnostics)
    signals = set(kinds.sensors | kinds.actions) if kinds is not None else set()
    problems.extend(_unknown_names(parts, names | set(groups) | signals, file, bool(signals)))
    if problems or not parts:
        return None, problems
    formula = substitute(conjoin(parts), group_expansion(groups))
    ltl_part = parts[-1] if isinstance(ltl, str) else None
    if _depth(formula) > NESTING_LIMIT:
        return None, [_too_deep(formula, ltl_part, data, doc, file, groups, known)]
    too_large = _normal_form_too_large(formula, ltl_part, data, doc, file, groups, known)
    if too_large is not None:
        return None, [too_large]
    return formula, []


def _depth(formula: Formula) -> int:
    """How many levels deep ``formula`` is nested: the depth the LTL reader counts (L005)."""
    deepest = 0
    stack = [(formula, 1)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        stack.extend((child, depth + 1) for child in node.children())
    return deepest


def _largest_part(
    ltl: Formula | None,
    data: Mapping[str, Any],
    groups: Mapping[str, list[str]],
    kinds: NameKinds,
    measure: Callable[[Formula], int],
) -> tuple[Path, str]:
    """The path and name of the task entry (a phrase, or ``ltl``) whose formula, its groups
    expanded, ``measure`` finds largest: the one to blame when the whole task is too large."""
    expansion = group_expansion(groups)
    where: Path = ("ltl",)
    what = "`ltl`"
    largest = -1 if ltl is None else measure(substitute(ltl, expansion))
    for index, phrase in enumerate(data.get("task") or ()):
        part = compile_phrase(phrase, groups=groups, kinds=kinds)
        size = measure(substitute(part, expansion))
        if size > largest:
            where, what, largest = ("task", index), f"task phrase {index + 1}", size
    return where, what


def _too_deep(
    formula: Formula,
    ltl: Formula | None,
    data: Mapping[str, Any],
    doc: PositionedDocument,
    file: str,
    groups: Mapping[str, list[str]],
    kinds: NameKinds,
) -> Diagnostic:
    """L005 for a task whose formula is nested deeper than the LTL reader accepts (a long
    ``then`` chain), placed at its deepest phrase (or at ``ltl``): every later stage reads
    the formula back, so the mission is refused before them."""
    where, what = _largest_part(ltl, data, groups, kinds, _depth)
    line, col = _ltl_position(doc, where)
    return error(
        "L005",
        f"the LTL formula is nested more than {NESTING_LIMIT} levels deep "
        f"({_depth(formula)} with {what})",
        hint="each `then` nests two levels: shorten the chain, or split the task into "
        "several phrases or conjuncts",
        file=file,
        line=line,
        col=col,
        path=json_path(where),
    )


def _normal_form_too_large(
    formula: Formula,
    ltl: Formula | None,
    data: Mapping[str, Any],
    doc: PositionedDocument,
    file: str,
    groups: Mapping[str, list[str]],
    kinds: NameKinds,
) -> Diagnostic | None:
    """P041 for a task whose negation normal form is beyond the translation's budget (a chain
    of ``<->``), placed at the phrase (or ``ltl``) with the largest normal form: every
    command that translates the task would refuse it, at no place in the file."""
    refusal = normal_form_refusal(formula)
    if refusal is None:
        return None
    where, _ = _largest_part(ltl, data, groups, kinds, normal_form_size)
    line, col = _ltl_position(doc, where)
    return dataclasses.replace(refusal, file=file, line=line, col=col, path=json_path(where))


def place_translation_refusal(
    refusal: Diagnostic, mission: Mission, text: str | None = None
) -> Diagnostic:
    """``refusal`` (P041, the task's automaton beyond the translation's budget) placed in the
    mission's file: at the task entry (a phrase, or ``ltl``) whose automaton alone is beyond
    the budget, or, when none is, at the ``task:`` key (``ltl:`` without phrases) with a hint
    that the conjunction of the entries is what is too large.

    ``text`` is the mission's YAML when it is not read from ``mission.source``; a refusal
    that already has a line, or whose mission text cannot be read any more, is returned as it
    is.
    """
    if refusal.line is not None or mission.source is None:
        return refusal
    file = mission.source
    if text is None:
        try:
            text = _read(file)
        except (InvalidInputError, UsageError):  # gone or changed since it was loaded
            return refusal
    doc = load_positioned(text, file, lazy=True)[0]
    if doc is None or not isinstance(doc.data, Mapping):
        return refusal
    data = doc.data
    groups = {name: list(members) for name, members in mission.groups.items()}
    reactive = mission.reactive
    kinds = NameKinds(
        regions=frozenset(mission.region_names),
        groups=frozenset(groups),
        sensors=frozenset(reactive.sensor_names if reactive else ()),
        actions=frozenset(reactive.actions if reactive else ()),
    )
    ltl = mission.ltl if mission.ltl and mission.ltl.strip() else None
    ltl_part = None if ltl is None else _parse_task_ltl(ltl)
    entries = len(mission.task) + (ltl is not None)
    # the entry with the largest normal form is the likeliest culprit: its translation alone,
    # within the same budget, tells whether it is one
    where, _ = _largest_part(ltl_part, data, groups, kinds, normal_form_size)
    if entries == 1 or _translation_refused(where, ltl_part, data, groups, kinds):
        line, col = _ltl_position(doc, where)
        return dataclasses.replace(refusal, file=file, line=line, col=col, path=json_path(where))
    key: Path = ("task",) if mission.task else ("ltl",)
    line, col = doc.key_at(key)
    return dataclasses.replace(
        refusal,
        file=file,
        line=line,
        col=col,
        path=json_path(key),
        hint=f"no entry alone is too large: the conjunction of the task's {entries} entries "
        "is; split the task into smaller missions, or write fewer independent goals "
        "(each `F a` or `G F a` beside the others can double the automaton)",
    )


def _parse_task_ltl(text: str) -> Formula:
    from tlmpc.ltl.parser import parse_ltl  # lark: only for missions with `ltl`

    return parse_ltl(text)


def _translation_refused(
    where: Path,
    ltl: Formula | None,
    data: Mapping[str, Any],
    groups: Mapping[str, list[str]],
    kinds: NameKinds,
) -> bool:
    """Whether the translation refuses (P041) the task entry at ``where`` alone."""
    from tlmpc.automata.translate import translate

    part = (
        ltl
        if where == ("ltl",)
        else compile_phrase(data["task"][where[1]], groups=groups, kinds=kinds)
    )
    assert part is not None  # the largest part is `ltl` only when the mission has one
    try:
        translate(substitute(part, group_expansion(groups)), simplify=False)
    except UsageError as exc:
        return any(d.code == "P041" for d in exc.diagnostics)
    return False


def _unknown_names(
    formulas: list[Formula], known: set[str], file: str, reactive: bool
) -> list[Diagnostic]:
    """L010 for every proposition that names nothing the mission declares."""
    problems: list[Diagnostic] = []
    where = (
        "regions, groups, sensors and actions are declared under `regions:`, `groups:`, "
        "`sensors:` and `actions:`"
        if reactive
        else "regions and groups are declared under `regions:` and `groups:`"
    )
    from tlmpc.ltl.fused import fused_operators

    for formula in formulas:
        for node in formula.walk():
            if isinstance(node, Prop) and node.name not in known:
                close = difflib.get_close_matches(node.name, sorted(known), n=1, cutoff=0.5)
                fused = fused_operators(node.name, sorted(known))
                span = node.span
                problems.append(
                    error(
                        "L010",
                        f"unknown {'name' if reactive else 'region'} {node.name!r}",
                        hint=f"did you mean `{fused}`? operators are words of their own: "
                        f"`{node.name}` is one proposition named {node.name!r}"
                        if fused
                        else (f"did you mean {close[0]!r}? " if close else "") + where,
                        file=file,
                        line=span.line if span else None,
                        col=span.col if span else None,
                    )
                )
    return problems


def _reactive(
    data: Mapping[str, Any],
    doc: PositionedDocument,
    file: str,
    names: set[str],
    groups: Mapping[str, list[str]],
) -> tuple[Reactive | None, NameKinds | None, list[Diagnostic]]:
    """Sensors, actions and assumptions (None, None when the mission has none of them)."""
    if not any(key in data for key in ("sensors", "actions", "assumptions")):
        return None, None, []
    problems: list[Diagnostic] = []
    sensors = dict(data.get("sensors") or {})
    actions = dict(data.get("actions") or {})
    taken: dict[str, str] = dict.fromkeys(names, "region")
    taken.update(dict.fromkeys(groups, "group"))
    for key, declared in (("sensors", sensors), ("actions", actions)):
        for name in declared:
            if name in taken:
                line, col = doc.key_at((key, name))
                problems.append(
                    error(
                        "S013",
                        f"{name!r} is declared as a {key[:-1]} and as a {taken[name]}",
                        hint="a name means one thing: rename one of them",
                        file=file,
                        line=line,
                        col=col,
                    )
                )
            elif name in MOTION_NAMES:
                line, col = doc.key_at((key, name))
                problems.append(
                    error(
                        "S013",
                        f"the {key[:-1]} {name!r} has the name of a variable of the robot's "
                        f"motion in the reactive game ({', '.join(MOTION_NAMES)})",
                        hint=f"rename the {key[:-1]} (e.g. {name}_{key[:-1]})",
                        file=file,
                        line=line,
                        col=col,
                    )
                )
            taken[name] = key[:-1]
    kinds = NameKinds(
        regions=frozenset(names),
        groups=frozenset(groups),
        sensors=frozenset(sensors),
        actions=frozenset(actions),
    )
    assumptions: list[TaskPart] = []
    for index, text in enumerate(data.get("assumptions") or ()):
        from tlmpc.ltl.parser import parse_ltl  # lark: only for missions with assumptions

        line, col = _ltl_position(doc, ("assumptions", index))
        place = doc.places(("assumptions", index))
        try:
            formula = parse_ltl(text, file=file, line=line, col=col, place=place)
        except InvalidInputError as exc:
            problems.extend(exc.diagnostics)
            continue
        problems.extend(_unknown_names([formula], set(taken), file, True))
        for node in formula.walk():
            if isinstance(node, Prop) and node.name in actions:
                span = node.span
                problems.append(
                    error(
                        "Q101",
                        f"the assumption names the action {node.name!r}",
                        hint="assumptions say what the environment does (sensors, and where "
                        "the robot is); what the robot does belongs in the task",
                        file=file,
                        line=span.line if span else line,
                        col=span.col if span else col,
                    )
                )
        assumptions.append(
            TaskPart(
                text=text,
                formula=substitute(formula, group_expansion(groups)),
                line=line,
                col=col,
            )
        )
    reactive = Reactive(
        sensors=tuple(
            Sensor(name=name, **{k: str(v) for k, v in (binding or {}).items()})
            for name, binding in sensors.items()
        ),
        actions=tuple(actions),
        assumptions=tuple(assumptions),
    )
    return reactive, kinds, problems


def _task_positions(
    data: Mapping[str, Any], doc: PositionedDocument
) -> tuple[tuple[int, int], ...]:
    """Where each task phrase, then the ``ltl`` string, starts (for explanations)."""
    positions = [_ltl_position(doc, ("task", i)) for i in range(len(data.get("task") or []))]
    ltl = data.get("ltl")
    if isinstance(ltl, str) and ltl.strip():
        positions.append(_ltl_position(doc, ("ltl",)))
    return tuple(positions)


def _task_places(
    data: Mapping[str, Any], doc: PositionedDocument
) -> tuple[ScalarPlaces | None, ...]:
    """Where each character of each task phrase, then of the ``ltl`` string, is written (None
    for a one-line plain string: its start and the offset place it)."""
    places = [doc.places(("task", i)) for i in range(len(data.get("task") or []))]
    ltl = data.get("ltl")
    if isinstance(ltl, str) and ltl.strip():
        places.append(doc.places(("ltl",)))
    return tuple(places)


#: What ``_shapes`` finds: the boundary, holes and regions that passed, the problems, the
#: further pieces, and whether the regions' (and a map's groups') names are all known.
Shapes = tuple[
    CheckedShape | None, list[CheckedShape], dict[str, CheckedShape], list[Diagnostic], Pieces, bool
]


def _shapes(
    data: Mapping[str, Any], doc: PositionedDocument, file: str, refusals: _Refusals
) -> Shapes:
    """The workspace's and the regions' shapes, each checked when it passed the schema (a
    map only when the workspace, the robot, the regions and the groups passed it whole)."""
    problems: list[Diagnostic] = []
    workspace = data.get("workspace") if refusals.readable(("workspace",)) else None
    told = not isinstance(workspace, dict)  # refused or missing: the schema said so
    if not isinstance(workspace, dict):
        workspace = {}
    if "map" in workspace:
        if not all(refusals.clean((key,)) for key in ("workspace", "robot", "regions", "groups")):
            return None, [], {}, [], [], False
        return (*_map_shapes(data, doc, file), True)
    if "boundary" not in workspace and not told:
        line, col = doc.value_at(("workspace",))
        problems.append(
            error(
                "S002",
                "'boundary' is missing (required): give workspace.boundary or workspace.map",
                hint="see docs/mission-format.md for the keys",
                file=file,
                line=line,
                col=col,
                path="$.workspace",
            )
        )

    def check(shape: Any, path: Path, what: str) -> CheckedShape | None:
        if not refusals.clean(path):
            return None  # the schema's problem is told; its geometry would mean nothing
        checked, found = check_shape(shape, path, what, file, doc.value_at)
        problems.extend(found)
        return checked

    def items(value: Any, path: Path) -> list[tuple[int, Any]]:
        """The entries of the list at ``path`` that passed the schema, with their indices."""
        if not isinstance(value, list) or not refusals.readable(path):
            return []
        return [(i, item) for i, item in enumerate(value) if refusals.clean((*path, i))]

    boundary = (
        check(workspace["boundary"], ("workspace", "boundary"), "workspace boundary")
        if "boundary" in workspace
        else None
    )
    holes: list[CheckedShape] = []
    for index, hole in items(workspace.get("holes"), ("workspace", "holes")):
        checked = check(hole, ("workspace", "holes", index), f"hole {index}")
        if checked is not None:
            holes.append(checked)
    components: Pieces = []
    listed = workspace.get("components")
    for number, component in enumerate(listed if isinstance(listed, list) else []):
        where: Path = ("workspace", "components", number)
        if not isinstance(component, dict) or not refusals.readable(where):
            continue
        piece = check(
            component.get("boundary"), (*where, "boundary"), f"boundary of component {number}"
        )
        piece_holes: list[CheckedShape] = []
        for index, hole in items(component.get("holes"), (*where, "holes")):
            checked = check(hole, (*where, "holes", index), f"hole {index} of component {number}")
            if checked is not None:
                piece_holes.append(checked)
        if piece is not None:
            components.append((piece, piece_holes))
    regions: dict[str, CheckedShape] = {}
    declared = data.get("regions") if refusals.readable(("regions",)) else None
    for name, shape in (declared if isinstance(declared, dict) else {}).items():
        checked = check(shape, ("regions", name), f"region {name!r}")
        if checked is not None:
            regions[name] = checked
    return boundary, holes, regions, problems, components, True


def _map_shapes(
    data: Mapping[str, Any], doc: PositionedDocument, file: str
) -> tuple[
    CheckedShape | None, list[CheckedShape], dict[str, CheckedShape], list[Diagnostic], Pieces
]:
    """``workspace: {map: FILE.yaml, ...}``: the workspace and mask regions of a map."""
    from tlmpc.mission.map_workspace import map_shapes

    assert isinstance(data, dict)
    return map_shapes(data, doc, file)


def _body(
    data: Mapping[str, Any], doc: PositionedDocument, file: str
) -> tuple[tuple[float, Polygon | None], list[Diagnostic]]:
    """``robot.radius`` and ``robot.footprint``; ``workspace.inflate`` is a deprecated alias
    of the radius (with a map) and must agree with it when both are given."""
    robot = data["robot"]
    radius = float(robot.get("radius", 0.0))
    inflate = (data.get("workspace") or {}).get("inflate")
    problems: list[Diagnostic] = []
    if inflate is not None:
        if "radius" in robot and float(inflate) != radius:
            line, col = doc.value_at(("workspace", "inflate"))
            problems.append(
                error(
                    "R005",
                    f"workspace.inflate ({float(inflate):g}) disagrees with robot.radius "
                    f"({radius:g})",
                    hint="inflate is a deprecated alias of robot.radius: remove it",
                    file=file,
                    line=line,
                    col=col,
                    path="$.workspace.inflate",
                )
            )
        radius = float(inflate)
    footprint: Polygon | None = None
    if "footprint" in robot:
        checked, found = check_shape(
            robot["footprint"], ("robot", "footprint"), "robot footprint", file, doc.value_at
        )
        problems.extend(found)
        if checked is not None:
            footprint = checked.points
    return (radius, footprint), problems


#: The longest time, in seconds, the robot may take to cross the workspace's bounding box at
#: ``robot.max_speed`` (S010 below): a trace holds times up to 1e12 (V024), so a slower robot
#: could not even cross once in one (1e-11 over 14 m compiled to a trace V024 refused; 1e-10
#: compiles).  A map at the coordinates' bound (2.8e9 across) checks at the default speed.
MAX_CROSSING_SECONDS = 1e12


def _speed(
    data: Mapping[str, Any],
    doc: PositionedDocument,
    file: str,
    boundary: CheckedShape | None,
    components: Pieces,
) -> list[Diagnostic]:
    """S010 for a ``robot.max_speed`` so small that crossing the workspace's bounding box
    would take longer than MAX_CROSSING_SECONDS (a positive 1e-12 over 14 m, or a subnormal
    1e-320)."""
    robot = data["robot"]
    if boundary is None or "max_speed" not in robot:
        return []
    speed = float(robot["max_speed"])
    if speed * MAX_CROSSING_SECONDS >= 3 * MISSION_COORDINATE_LIMIT:
        return []  # no workspace within the coordinates' bound is that wide
    bounds = [_bounds(shape) for shape in (boundary, *(piece for piece, _ in components))]
    width = max(b[2] for b in bounds) - min(b[0] for b in bounds)
    height = max(b[3] for b in bounds) - min(b[1] for b in bounds)
    diagonal = math.hypot(width, height)
    if diagonal <= speed * MAX_CROSSING_SECONDS:
        return []
    line, col = doc.value_at(("robot", "max_speed"))
    return [
        error(
            "S010",
            f"$.robot.max_speed: {speed:g} is too small: crossing the workspace "
            f"({diagonal:g} across) would take more than {MAX_CROSSING_SECONDS:g} s",
            hint=f"give a max_speed of at least {diagonal / MAX_CROSSING_SECONDS:.3g} "
            f"(the workspace's bounding-box diagonal / {MAX_CROSSING_SECONDS:g} s), "
            "or check its units",
            file=file,
            line=line,
            col=col,
            path="$.robot.max_speed",
        )
    ]


def _bounds(shape: CheckedShape) -> tuple[float, float, float, float]:
    """The shape's bounding box, from its shapely polygon when one was built (a large map's),
    else in plain Python (a small mission's check loads no geometry library)."""
    if shape.polygon is not None:
        return shapely_polygon(shape).bounds  # type: ignore[no-any-return]
    xs = [float(point[0]) for point in shape.points]
    ys = [float(point[1]) for point in shape.points]
    return min(xs), min(ys), max(xs), max(ys)


def _groups(
    data: Mapping[str, Any],
    doc: PositionedDocument,
    file: str,
    names: set[str],
    refusals: _Refusals,
) -> tuple[dict[str, list[str]], list[Diagnostic]]:
    """The groups that passed the schema, and S011/S012 for each."""
    problems: list[Diagnostic] = []
    groups: dict[str, list[str]] = {}
    for group, members in _passed_keys(data, "groups", refusals).items():
        if group in names:
            line, col = doc.key_at(("groups", group))
            problems.append(
                error(
                    "S012",
                    f"{group!r} names both a region and a group",
                    hint="rename one of them",
                    file=file,
                    line=line,
                    col=col,
                )
            )
        for index, member in enumerate(members):
            if member not in names:
                line, col = doc.value_at(("groups", group, index))
                close = difflib.get_close_matches(member, sorted(names), n=1)
                problems.append(
                    error(
                        "S011",
                        f"group {group!r} lists unknown region {member!r}",
                        hint=f"did you mean {close[0]!r}?" if close else "groups list region names",
                        file=file,
                        line=line,
                        col=col,
                    )
                )
        groups[group] = list(dict.fromkeys(members))
    return groups, problems


def _load(text: str, file: str, stem: str) -> tuple[Mission | None, list[Diagnostic]]:
    # Reading a large map builds millions of small lists and tuples, none of them in a cycle;
    # the cyclic collector would walk the growing heap again and again (half the time).
    paused = gc.isenabled()
    gc.disable()
    try:
        return _load_data(text, file, stem)
    finally:
        if paused:
            gc.enable()


def _load_data(text: str, file: str, stem: str) -> tuple[Mission | None, list[Diagnostic]]:
    doc, problems = load_positioned(text, file, lazy=True)
    if doc is None:
        return None, problems
    number_like = [p for p in problems if p.code == NUMBER_LIKE_TEXT]
    if len(number_like) < len(problems):
        # non-finite numbers, duplicate keys: the schema would mislead after these
        return None, problems
    problems = []
    if not isinstance(doc.data, dict):
        return None, [
            error(
                "S005",
                "a mission must be a mapping of keys to values",
                hint="start the file with `version: 1`",
                file=file,
                line=1,
                col=1,
            )
        ]
    schema_problems, refused = _schema_diagnostics(doc, file)
    problems.extend(_number_like_where_refused(number_like, schema_problems))
    refusals = _Refusals(refused)
    if not refusals.readable(()):
        return None, problems  # the document as a whole: nothing below it can be read
    data: dict[str, Any] = doc.data
    # Every later check reads only values that passed the schema: ``checked`` holds the
    # robot's and the workspace's keys that did (the shapes are taken one by one).
    checked = {
        **data,
        "robot": _passed_keys(data, "robot", refusals),
        "workspace": _passed_keys(data, "workspace", refusals),
    }
    boundary, holes, regions, found, components, names_complete = _shapes(data, doc, file, refusals)
    problems.extend(found)
    robot = checked["robot"]
    start = (float(robot["start"][0]), float(robot["start"][1])) if "start" in robot else None
    problems.extend(
        check_layout(
            boundary,
            holes,
            regions,
            start,
            ("robot", "start"),
            file,
            doc.value_at,
            components=components,
        )
    )
    body, found = _body(checked, doc, file)
    problems.extend(found)
    problems.extend(_speed(checked, doc, file, boundary, components))
    declared = data.get("regions") if refusals.readable(("regions",)) else None
    names = set(regions) | set(declared if isinstance(declared, dict) else ())
    groups, found = _groups(data, doc, file, names, refusals)
    problems.extend(found)
    # The names a task may use are complete only when every declaration passed the schema:
    # otherwise a name refused (or a map not read) would come back as a false L010.
    names_complete = (
        names_complete
        and isinstance(declared, dict)
        and all(map(_is_name, declared))
        and all(refusals.clean((key,)) for key in _DECLARATIONS)
    )
    if not names_complete:
        return None, problems
    reactive, kinds, found = _reactive(data, doc, file, names, groups)
    problems.extend(found)
    if not (refusals.clean(("task",)) and refusals.clean(("ltl",))):
        return None, problems
    formula, found = _check_task(data, doc, file, names, groups, kinds)
    problems.extend(found)
    if problems or boundary is None or formula is None or start is None:
        return None, problems
    options = data.get("options") or {}
    defaults = Options()
    mission = Mission(
        name=str(data.get("name") or stem),
        workspace=Workspace(
            boundary=boundary.points,
            holes=tuple(h.points for h in holes),
            components=tuple(
                Component(boundary=b.points, holes=tuple(h.points for h in hs))
                for b, hs in components
            ),
            map_tolerance=float(data["workspace"].get("tolerance", 0.0))
            if "map" in data["workspace"]
            else 0.0,
        ),
        regions=tuple(Region(name=n, polygon=shape.points) for n, shape in regions.items()),
        robot=Robot(
            start=start,
            max_speed=float(robot.get("max_speed", 1.0)),
            disturbance=float(robot.get("disturbance", 0.0)),
            model=robot.get("model", "point"),
            offset=float(robot.get("offset", 0.0)),
            radius=body[0],
            footprint=body[1],
        ),
        formula=formula,
        groups={g: tuple(m) for g, m in groups.items()},
        task=tuple(data.get("task") or ()),
        ltl=data.get("ltl"),
        options=Options(
            min_angle=options.get("min_angle", defaults.min_angle),
            max_area=options.get("max_area", defaults.max_area),
            # a task with time bounds is planned for minimum time unless the mission says
            # otherwise (docs/planning.md)
            cost=options.get("cost", "time" if bounded_operators(formula) else defaults.cost),
            beta=float(options.get("beta", defaults.beta)),
            boundary=options.get("boundary", defaults.boundary),
            margin=float(options["margin"]) if "margin" in options else None,
            goal_depth=float(options["goal_depth"]) if "goal_depth" in options else None,
        ),
        source=file,
        task_positions=_task_positions(data, doc),
        task_places=_task_places(data, doc),
        reactive=reactive,
    )
    return mission, []


#: The keys whose names a task or an assumption may use: checked only when all passed.
_DECLARATIONS = ("groups", "sensors", "actions", "assumptions")


def _passed_keys(data: Mapping[str, Any], key: str, refusals: _Refusals) -> dict[str, Any]:
    """The entries of the mapping ``data[key]`` that passed the schema ({} when it is no
    mapping, or was refused as a whole)."""
    section = data.get(key)
    if not isinstance(section, dict) or not refusals.readable((key,)):
        return {}
    return {name: value for name, value in section.items() if refusals.clean((key, name))}


def _read(path: str | FilePath) -> str:
    from tlmpc.io.inputs import read_bytes

    file = str(path)
    # a bounded read of a regular file: `check /dev/zero` or a FIFO is refused at once
    raw = read_bytes(
        FilePath(path), limit=MAX_BYTES, code="U001", too_large_code="U004", what="mission file"
    )
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InvalidInputError(
            error(
                "Y008",
                f"the file is not UTF-8 text ({exc.reason} at byte {exc.start})",
                hint="save it as UTF-8",
                file=file,
                line=1,
                col=1,
            )
        ) from None


def check_text(text: str, filename: str = "<string>") -> list[Diagnostic]:
    """Every problem of the mission ``text`` (empty when valid), best first."""
    _, problems = _load(text, filename, FilePath(filename).stem)
    return best_first(problems)


def inspect_file(path: str | FilePath) -> tuple[Mission | None, list[Diagnostic]]:
    """The mission at ``path`` (None when invalid) and its problems, best first.

    Raises UsageError when the file cannot be read at all.
    """
    try:
        text = _read(path)
    except InvalidInputError as exc:
        return None, list(exc.diagnostics)
    mission, problems = _load(text, str(path), FilePath(path).stem)
    return mission, best_first(problems)


def check_file(path: str | FilePath) -> list[Diagnostic]:
    """Every problem of the mission file at ``path``; raises UsageError if unreadable."""
    return inspect_file(path)[1]


def load_mission_text(text: str, filename: str = "<string>") -> Mission:
    """Load a mission from YAML text; raises InvalidInputError with all the problems."""
    mission, problems = _load(text, filename, FilePath(filename).stem)
    if mission is None:
        raise InvalidInputError(
            best_first(problems) or [error("S000", "invalid mission", file=filename)]
        )
    return mission


def load_mission(path: str | FilePath) -> Mission:
    """Load the mission file at ``path`` (UsageError if unreadable, InvalidInputError if bad)."""
    return load_mission_text(_read(path), str(path))
