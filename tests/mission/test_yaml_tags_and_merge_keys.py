"""YAML features a mission does not use are refused at their place, never read another way:
a tag on a mapping or list as on a scalar (Y004, whose message is the problem alone), and a
merge key `<<`, which PyYAML's own reader would merge (Y006)."""

from __future__ import annotations

import pytest
import yaml

from tlmpc.base.errors import InvalidInputError
from tlmpc.mission.load import load_mission_text

BASE = """\
version: 1
name: tags
workspace:
  boundary: {boundary}
regions:
  a: {region}
robot: {robot}
task: [visit a]
"""
PLAIN = {
    "boundary": "{rect: [0, 0, 10, 10]}",
    "region": "{rect: [1, 1, 2, 2]}",
    "robot": "{start: [5, 5]}",
}


def _problems(text: str) -> list[tuple[str, int, int, str, str | None]]:
    try:
        load_mission_text(text, "m.yaml")
    except InvalidInputError as exc:
        return [(d.code, d.line or 0, d.col or 0, d.message, d.hint) for d in exc.diagnostics]
    return []


def _place(text: str, needle: str) -> tuple[int, int]:
    at = text.index(needle)
    return text.count("\n", 0, at) + 1, at - (text.rfind("\n", 0, at) + 1) + 1


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("region", "!custom {rect: [1, 1, 2, 2]}"),
        ("region", "!!python/object:os.system {rect: [1, 1, 2, 2]}"),
        ("region", "!!omap [rect: [1, 1, 2, 2]]"),
        ("boundary", "{rect: !!set {0, 1}}"),
        ("robot", "{start: !point [5, 5]}"),
    ],
)
def test_a_tagged_mapping_or_list_is_refused_at_its_tag(key: str, value: str) -> None:
    text = BASE.format(**{**PLAIN, key: value})
    tag = value[value.index("!") :].split(" ")[0]
    ((code, line, col, _, hint),) = _problems(text)
    assert (code, line, col) == ("Y004", *_place(text, tag))
    assert "tag" in (hint or "")


def test_the_tags_a_mapping_or_list_has_anyway_are_read() -> None:
    text = BASE.format(**{**PLAIN, "boundary": "!!map {rect: !!seq [0, 0, 10, 10]}"})
    assert _problems(text) == []


@pytest.mark.parametrize("value", ["!custom 5", "!!float abc", "!!timestamp 2001-99-99"])
def test_a_scalar_that_cannot_be_read_is_described_without_the_parser_internals(
    value: str,
) -> None:
    text = BASE.format(**{**PLAIN, "region": f"{{rect: [1, 1, 2, {value}]}}"})
    ((code, line, col, message, _),) = _problems(text)
    assert (code, line, col) == ("Y004", *_place(text, value))
    assert "\n" not in message
    assert "<unicode string>" not in message
    assert "line" not in message


@pytest.mark.parametrize(
    "robot",
    [
        "\n  <<: {start: [5, 5]}\n  max_speed: 2",
        "\n  max_speed: 2\n  <<: [{start: [5, 5]}, {radius: 0}]",
        "{<<: {start: [5, 5]}}",
    ],
)
def test_a_merge_key_is_refused_at_the_key(robot: str) -> None:
    text = BASE.format(**{**PLAIN, "robot": robot})
    # PyYAML merges it: read as a key named "<<" the mission would mean something else
    assert "<<" not in yaml.safe_load(text)["robot"]
    ((code, line, col, message, _),) = _problems(text)
    assert (code, line, col) == ("Y006", *_place(text, "<<"))
    assert "merge" in message


def test_a_quoted_key_named_like_a_merge_key_is_a_name() -> None:
    text = BASE.format(**PLAIN).replace("  a: ", '  "<<": ')
    codes = [p[0] for p in _problems(text)]
    assert "S008" in codes
    assert "Y006" not in codes
