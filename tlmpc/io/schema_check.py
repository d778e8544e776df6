"""The JSON Schemas: where they live, loading them, and checking documents against them.

A small yes/no JSON Schema (draft 2020-12) checker for the keywords tlmpc's schemas use
runs first.

jsonschema stays the validator that words every problem; importing it (with ``referencing``
and ``attrs``) costs a tenth of a second on every start, which is most of a ``tlmpc check``
of a valid mission.  :func:`is_valid` answers only "valid or not"; callers take a "valid"
as final and ask jsonschema for the messages otherwise.  A schema using a keyword this
module does not implement makes :func:`is_valid` return ``None`` (ask jsonschema).  The test
suite compares both on the shipped missions, every artifact and random mutations of them.
"""

from __future__ import annotations

import functools
import json
import re
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

#: Keywords that never change whether an instance is valid.
_ANNOTATIONS = frozenset(
    {"$id", "$schema", "$comment", "$defs", "title", "description", "default", "examples", "format"}
)

Check = Callable[[Any], bool]

#: The largest size of a mission coordinate: the mission schema's ``coordinate`` bound (S010).
#: The loader's quick shape checks and the map importer apply it too, so a mission written
#: from a map is one ``tlmpc check`` accepts (a test keeps it equal to the schema's).
MISSION_COORDINATE_LIMIT = 1e9


class _Unsupported(Exception):
    """The schema uses a keyword this checker does not implement."""


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


_TYPES: dict[str, Check] = {
    "object": lambda v: isinstance(v, dict),
    "array": lambda v: isinstance(v, list),
    "string": lambda v: isinstance(v, str),
    "boolean": lambda v: isinstance(v, bool),
    "null": lambda v: v is None,
    "number": _is_number,
    "integer": lambda v: _is_number(v) and (isinstance(v, int) or float(v).is_integer()),
}


def _equal(one: Any, two: Any) -> bool:
    """JSON equality, as jsonschema's ``const`` and ``enum`` (true is not 1)."""
    if isinstance(one, bool) or isinstance(two, bool):
        return isinstance(one, bool) and isinstance(two, bool) and one == two
    if isinstance(one, str) or isinstance(two, str):
        return isinstance(one, str) and isinstance(two, str) and one == two
    if _is_number(one) and _is_number(two):
        return bool(one == two)
    if isinstance(one, list) and isinstance(two, list):
        return len(one) == len(two) and all(_equal(a, b) for a, b in zip(one, two, strict=True))
    if isinstance(one, dict) and isinstance(two, dict):
        return one.keys() == two.keys() and all(_equal(one[k], two[k]) for k in one)
    return bool(one is None and two is None)


class _Compiler:
    def __init__(self, root: Mapping[str, Any]) -> None:
        self.root = root
        self.refs: dict[str, Check] = {}

    def ref(self, target: str) -> Check:
        if not target.startswith("#/"):
            raise _Unsupported(target)
        if target not in self.refs:
            slot: list[Check] = []
            self.refs[target] = lambda v: slot[0](v)  # recursion-safe placeholder
            node: Any = self.root
            for part in target[2:].split("/"):
                node = node[part.replace("~1", "/").replace("~0", "~")]
            slot.append(self.compile(node))
        return self.refs[target]

    def compile(self, schema: Any) -> Check:
        if schema is True:
            return lambda v: True
        if schema is False:
            return lambda v: False
        if not isinstance(schema, dict):
            raise _Unsupported(repr(schema))
        checks: list[Check] = []
        for key, value in schema.items():
            if key in _ANNOTATIONS:
                continue
            checks.append(self.keyword(key, value, schema))
        if len(checks) == 1:
            return checks[0]
        return lambda v: all(check(v) for check in checks)

    def keyword(self, key: str, value: Any, schema: Mapping[str, Any]) -> Check:
        if key == "$ref":
            return self.ref(value)
        if key == "type":
            names = [value] if isinstance(value, str) else list(value)
            tests = [_TYPES[n] for n in names]
            return lambda v: any(t(v) for t in tests)
        if key == "const":
            return lambda v: _equal(v, value)
        if key == "enum":
            return lambda v: any(_equal(v, option) for option in value)
        if key in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
            # jsonschema's failure conditions, negated (so NaN passes, as it does there)
            fails: Callable[[Any], bool] = {
                "minimum": lambda v: v < value,
                "maximum": lambda v: v > value,
                "exclusiveMinimum": lambda v: v <= value,
                "exclusiveMaximum": lambda v: v >= value,
            }[key]
            return lambda v: not _is_number(v) or not fails(v)
        if key == "pattern":
            regex = re.compile(value)
            return lambda v: not isinstance(v, str) or regex.search(v) is not None
        if key == "minLength":
            return lambda v: not isinstance(v, str) or len(v) >= value
        if key == "maxLength":
            return lambda v: not isinstance(v, str) or len(v) <= value
        if key == "minItems":
            return lambda v: not isinstance(v, list) or len(v) >= value
        if key == "maxItems":
            return lambda v: not isinstance(v, list) or len(v) <= value
        if key == "minProperties":
            return lambda v: not isinstance(v, dict) or len(v) >= value
        if key == "required":
            return lambda v: not isinstance(v, dict) or all(name in v for name in value)
        if key == "items":
            item = self.compile(value)
            return lambda v: not isinstance(v, list) or all(item(x) for x in v)
        if key == "properties":
            props = {name: self.compile(sub) for name, sub in value.items()}
            return lambda v: (
                not isinstance(v, dict) or all(props[k](x) for k, x in v.items() if k in props)
            )
        if key == "additionalProperties":
            if "patternProperties" in schema:
                raise _Unsupported(key)
            known = frozenset(schema.get("properties", {}))
            extra = self.compile(value)
            return lambda v: (
                not isinstance(v, dict) or all(extra(x) for k, x in v.items() if k not in known)
            )
        if key == "propertyNames":
            name_check = self.compile(value)
            return lambda v: not isinstance(v, dict) or all(name_check(k) for k in v)
        if key == "anyOf":
            options = [self.compile(sub) for sub in value]
            return lambda v: any(option(v) for option in options)
        if key == "allOf":
            parts = [self.compile(sub) for sub in value]
            return lambda v: all(part(v) for part in parts)
        if key == "oneOf":
            choices = [self.compile(sub) for sub in value]
            return lambda v: sum(1 for choice in choices if choice(v)) == 1
        if key == "not":
            inner = self.compile(value)
            return lambda v: not inner(v)
        if key == "if":
            condition = self.compile(value)
            then = self.compile(schema.get("then", True))
            otherwise = self.compile(schema.get("else", True))
            return lambda v: then(v) if condition(v) else otherwise(v)
        if key in ("then", "else"):
            return lambda v: True  # applied by "if"; alone they mean nothing
        raise _Unsupported(key)


@functools.cache
def _checker(name: str) -> Check | None:
    schema = load_schema(name)
    try:
        return _Compiler(schema).compile(schema)
    except _Unsupported:
        return None


def is_valid(document: Any, name: str) -> bool | None:
    """Whether ``document`` is valid against schema ``name``; None when this cannot tell."""
    check = _checker(name)
    if check is None:
        return None
    try:
        return check(document)
    except (TypeError, ValueError, RecursionError):
        return None  # an instance jsonschema itself must judge (and word)


def schema_dir() -> Path:
    """The folder holding the JSON Schemas (packaged copy first, then the source tree)."""
    package = Path(__file__).resolve().parent.parent  # tlmpc/
    for folder in (package / "schemas", package.parent / "schemas"):  # installed, source tree
        if folder.is_dir():
            return folder
    from importlib import resources  # not at the top: it imports tempfile, shutil, random

    packaged = resources.files("tlmpc") / "schemas"
    if packaged.is_dir():
        return Path(str(packaged))
    return package.parent / "schemas"


@functools.cache
def load_schema(name: str) -> dict[str, Any]:
    """The schema ``schemas/<name>.schema.json`` (e.g. ``"mission"``, ``"abstraction"``)."""
    path = schema_dir() / f"{name}.schema.json"
    with path.open(encoding="utf-8") as handle:
        schema: dict[str, Any] = json.load(handle)
    return schema


def validation_errors(document: Any, name: str) -> list[str]:
    """Messages for every way ``document`` violates schema ``name`` (empty when valid)."""
    if is_valid(document, name):
        return []  # jsonschema is imported only to word the problems
    import jsonschema

    validator = jsonschema.Draft202012Validator(load_schema(name))
    return [
        f"{err.json_path}: {err.message}"
        for err in sorted(validator.iter_errors(document), key=lambda e: list(e.path))
    ]
