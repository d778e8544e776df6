"""A mission dict may hold any mapping, tuples, numpy numbers and arrays, and subclasses of
str, int and float (enum members): it means what the same mission of plain dicts, lists,
strings and numbers means.  Anything else is refused (U075) at its JSON path."""

from __future__ import annotations

import collections
import enum
import io
import types
from typing import Any

import numpy as np
import pytest
from ruamel.yaml import YAML

import tlmpc


class _Name(str):
    pass


class _Version(enum.IntEnum):
    ONE = 1


def _plain() -> dict[str, Any]:
    return {
        "version": 1,
        "name": "types",
        "workspace": {"boundary": {"rect": [0, 0, 10, 10]}},
        "regions": {"a": {"rect": [1, 1, 2, 2]}, "b": [[7, 7], [8, 7], [8, 8]]},
        "robot": {"start": [5.5, 5], "max_speed": 1.5},
        "task": ["visit a then b"],
    }


def _exotic() -> dict[str, object]:
    return {
        "version": _Version.ONE,
        "name": _Name("types"),
        "workspace": collections.OrderedDict(boundary={"rect": np.array([0, 0, 10, 10])}),
        "regions": collections.OrderedDict(
            a={"rect": (1, 1, np.int64(2), 2)}, b=np.array([[7, 7], [8, 7], [8, 8]])
        ),
        "robot": types.MappingProxyType(
            {"start": [np.float64(5.5), np.int32(5)], "max_speed": np.float32(1.5)}
        ),
        "task": (_Name("visit a then b"),),
    }


def _round_trip() -> object:
    """The plain mission as ruamel.yaml's round-trip reader gives it (CommentedMap, CommentedSeq,
    ScalarFloat): how a program edits a mission's YAML keeping its comments."""
    import yaml

    return YAML().load(io.StringIO(yaml.safe_dump(_plain())))


@pytest.mark.parametrize("make", [_exotic, _round_trip])
def test_a_dict_of_other_types_means_the_plain_mission(make: object) -> None:
    expected = tlmpc.compile(_plain(), until="load").artifacts["mission.json"]
    mission = make()  # type: ignore[operator]
    assert tlmpc.check(mission) == []
    assert tlmpc.compile(mission, until="load").artifacts["mission.json"] == expected


@pytest.mark.parametrize(
    ("where", "value", "path"),
    [
        (("regions", "a"), {1, 2}, "$.regions.a"),
        (("robot", "start"), [object(), 1], "$.robot.start[0]"),
        (("regions",), {(1, 2): {"rect": [1, 1, 2, 2]}}, "$.regions"),
        # a key that is no identifier is written as JSON paths write it
        (("regions", "my room"), {"rect": [1, 1, object()]}, '$.regions["my room"].rect[2]'),
    ],
)
def test_other_values_are_refused_at_their_path(
    where: tuple[str, ...], value: object, path: str
) -> None:
    mission: dict[str, Any] = _plain()
    parent = mission
    for key in where[:-1]:
        parent = parent[key]
    parent[where[-1]] = value
    with pytest.raises(tlmpc.TlmpcError) as refused:
        tlmpc.check(mission)
    (diagnostic,) = refused.value.diagnostics
    assert diagnostic.code == "U075"
    assert f" at {path}: " in diagnostic.message


def test_a_dict_that_holds_itself_is_refused() -> None:
    mission = _plain()
    mission["robot"]["self"] = mission
    with pytest.raises(tlmpc.TlmpcError) as refused:
        tlmpc.compile(mission)
    assert refused.value.diagnostics[0].code == "U075"
