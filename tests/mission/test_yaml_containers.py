"""Containers where YAML allows them and a mission does not: as keys, under repeated keys."""

from __future__ import annotations

import pytest

from tlmpc.mission.yamlpos import load_positioned


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ("a:\n  ? [1, 2]\n  : 3\n", "2:5"),
        ("a: {[1]: 2}\n", "1:5"),
        ("a:\n  b: 1\n  ? {c: 1}\n  : 2\n", "3:5"),
        ("- x: 1\n  ? [1]\n  : 2\n", "2:5"),
    ],
)
def test_a_container_as_a_key_is_refused_where_it_stands(text: str, where: str) -> None:
    _, problems = load_positioned(text, "m.yaml")
    assert [p.code for p in problems] == ["Y006"]
    assert problems[0].format().startswith(f"m.yaml:{where}: error[Y006]")


def test_a_repeated_key_with_a_container_value_keeps_the_first() -> None:
    doc, problems = load_positioned("a: {b: 1, b: [1, 2], c: {d: 3}}\n", "m.yaml")
    assert [p.code for p in problems] == ["Y002"]
    assert doc is not None
    assert doc.data == {"a": {"b": 1, "c": {"d": 3}}}
    assert doc.value_at(("a", "c", "d")) == (1, 29)
