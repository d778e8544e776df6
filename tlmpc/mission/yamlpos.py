"""YAML to plain data with a position for every value, key and list item.

PyYAML silently keeps the last of two equal keys and gives positions only on its node graph,
so we compose the node graph ourselves, convert it to plain data and record, for every JSON
path, where its value and (for mapping entries) its key start.  Duplicate keys, alias bombs,
too deep nesting and non-finite numbers become diagnostics instead of surprises.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import yaml

from tlmpc.errors import Diagnostic, error

Path = tuple[str | int, ...]

#: libyaml's loader when PyYAML was built with it (ten times faster), same nodes and marks.
_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

#: Refuse documents that expand to more nodes than this (a "billion laughs" alias bomb).
MAX_NODES = 2_000_000
#: Refuse nesting deeper than this (PyYAML's composer is recursive).
MAX_DEPTH = 64


@dataclass(slots=True)
class PositionedDocument:
    """Plain data plus 1-based (line, col) positions keyed by JSON path."""

    data: Any
    values: dict[Path, tuple[int, int]] = field(default_factory=dict)
    keys: dict[Path, tuple[int, int]] = field(default_factory=dict)
    quoted: dict[Path, bool] = field(default_factory=dict)
    block: dict[Path, bool] = field(default_factory=dict)

    def value_at(self, path: Path) -> tuple[int, int]:
        """Position of the value at ``path``, or of its deepest known ancestor."""
        for cut in range(len(path), -1, -1):
            if path[:cut] in self.values:
                return self.values[path[:cut]]
        return (1, 1)

    def key_at(self, path: Path) -> tuple[int, int]:
        """Position of the key of the entry at ``path`` (its value's when not a mapping entry)."""
        return self.keys.get(path) or self.value_at(path)


def json_path(path: Path) -> str:
    """``$.regions.p1[0]`` for ``("regions", "p1", 0)``."""
    text = "$"
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else f".{part}"
    return text


def _mark(node: yaml.Node) -> tuple[int, int]:
    return node.start_mark.line + 1, node.start_mark.column + 1


class _Converter:
    def __init__(self, file: str) -> None:
        self.file = file
        self.doc = PositionedDocument(data=None)
        self.problems: list[Diagnostic] = []
        self.count = 0
        self.constructor = yaml.SafeLoader("")

    def scalar(self, node: yaml.ScalarNode, path: Path) -> Any:
        try:
            value = self.constructor.construct_object(node, deep=True)
        except (yaml.YAMLError, ValueError, OverflowError) as exc:
            line, col = _mark(node)
            self.problems.append(
                error(
                    "Y004",
                    f"cannot read the value {node.value!r}: {exc}",
                    file=self.file,
                    line=line,
                    col=col,
                    path=json_path(path),
                )
            )
            return None
        if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**15:
            value = float("inf") if value > 0 else float("-inf")
        if isinstance(value, float) and not math.isfinite(value):
            line, col = _mark(node)
            self.problems.append(
                error(
                    "Y005",
                    f"the number {node.value!r} is not finite",
                    hint="use a finite number (no .nan, .inf, or values too large for a float)",
                    file=self.file,
                    line=line,
                    col=col,
                    path=json_path(path),
                )
            )
        return value

    def convert(self, root: yaml.Node) -> Any:
        # Iterative on purpose: documents can be deep and the Python stack is not.
        result: dict[str, Any] = {}
        stack: list[tuple[yaml.Node, Path, Any, Any, int]] = [(root, (), result, "root", 0)]
        while stack:
            node, path, parent, slot, depth = stack.pop()
            self.count += 1
            if self.count > MAX_NODES:
                self.problems.append(
                    error(
                        "Y003",
                        "the document is too large (alias expansion?)",
                        file=self.file,
                        line=1,
                        col=1,
                        hint="missions do not need YAML aliases",
                    )
                )
                return None
            if depth > MAX_DEPTH:
                line, col = _mark(node)
                self.problems.append(
                    error(
                        "Y003",
                        f"the document is nested more than {MAX_DEPTH} levels deep",
                        file=self.file,
                        line=line,
                        col=col,
                    )
                )
                return None
            self.doc.values[path] = _mark(node)
            if isinstance(node, yaml.ScalarNode):
                value: Any = self.scalar(node, path)
                self.doc.quoted[path] = node.style in ("'", '"')
                self.doc.block[path] = node.style in ("|", ">")
            elif isinstance(node, yaml.SequenceNode):
                value = [None] * len(node.value)
                for index in range(len(node.value) - 1, -1, -1):
                    stack.append((node.value[index], (*path, index), value, index, depth + 1))
            elif isinstance(node, yaml.MappingNode):
                value = {}
                seen: dict[str, tuple[int, int]] = {}
                for key_node, value_node in node.value:
                    if not isinstance(key_node, yaml.ScalarNode):
                        line, col = _mark(key_node)
                        self.problems.append(
                            error(
                                "Y006",
                                "mapping keys must be plain names",
                                file=self.file,
                                line=line,
                                col=col,
                                path=json_path(path),
                            )
                        )
                        continue
                    key = str(key_node.value)
                    if key in seen:
                        line, col = _mark(key_node)
                        first = seen[key]
                        self.problems.append(
                            error(
                                "Y002",
                                f"duplicate key {key!r}",
                                file=self.file,
                                line=line,
                                col=col,
                                path=json_path((*path, key)),
                                hint=f"it was already given at line {first[0]}; YAML would "
                                "silently keep only the last one",
                            )
                        )
                        continue
                    seen[key] = _mark(key_node)
                    self.doc.keys[(*path, key)] = _mark(key_node)
                    value[key] = None
                    stack.append((value_node, (*path, key), value, key, depth + 1))
            else:  # pragma: no cover - the composer yields only these node kinds
                value = None
            if isinstance(parent, dict | list):
                parent[slot] = value
        self.doc.data = result.get("root")
        return self.doc.data


def load_positioned(text: str, file: str) -> tuple[PositionedDocument | None, list[Diagnostic]]:
    """Parse YAML ``text``; return the data with positions, or None and the diagnostics."""
    try:
        root = yaml.compose(text, Loader=_LOADER)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 1
        col = mark.column + 1 if mark is not None else 1
        problem = exc.problem or "invalid YAML"
        hint = "check indentation (spaces only, no tabs), quotes and brackets"
        if "\t" in problem or "tab" in problem:
            hint = "YAML does not allow tabs for indentation: use spaces"
        return None, [
            error("Y001", f"YAML syntax error: {problem}", hint=hint, file=file, line=line, col=col)
        ]
    except yaml.YAMLError as exc:
        return None, [error("Y001", f"YAML syntax error: {exc}", file=file, line=1, col=1)]
    except RecursionError:
        return None, [error("Y003", "the document is nested too deeply", file=file, line=1, col=1)]
    if root is None:
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
    converter = _Converter(file)
    converter.convert(root)
    return converter.doc, converter.problems
