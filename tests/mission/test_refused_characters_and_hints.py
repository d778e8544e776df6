"""A character YAML does not allow (NUL, a bell, U+FFFE ...) is placed at its own line and
column, in a mission and in a map's YAML; and every error a mission's reading or schema check
reports carries a hint (docs/errors.md: "a stable code, a position when it has one, and a
hint")."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from robot_data import image_from_free, write_map

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = (ROOT / "specs" / "reach-avoid.yaml").read_text()

#: Characters YAML refuses anywhere in a stream (YAML 1.1, section 5.1: the printable set).
REFUSED = [chr(c) for c in (*range(0x00, 0x09), 0x0B, 0x0C, *range(0x0E, 0x20), 0x7F)] + [
    "\x80",
    "\x9f",
    "\ufffe",
    "\uffff",
]


def _check(path: Path) -> tuple[int, dict[str, Any]]:
    out = io.StringIO()
    code = main(["check", "--json", str(path)], out=out, err=io.StringIO())
    return code, json.loads(out.getvalue())


def _place(text: str, index: int) -> tuple[int, int]:
    """1-based line and column of ``text[index]``, counted by hand (lines end at "\\n")."""
    return text.count("\n", 0, index) + 1, index - (text.rfind("\n", 0, index) + 1) + 1


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    where=st.integers(0, len(SPEC)),
    char=st.sampled_from(REFUSED),
    prefix=st.sampled_from(["", "é", "日本"]),
)
def test_a_refused_character_is_placed_where_it_is(
    tmp_path: Path, where: int, char: str, prefix: str
) -> None:
    # a multi-byte character before it: libyaml counts the offset in bytes, the file in characters
    text = "# " + prefix + "\n" + SPEC[:where] + char + SPEC[where:]
    path = tmp_path / "m.yaml"
    path.write_text(text, encoding="utf-8")
    code, envelope = _check(path)
    assert code == 1
    (diagnostic,) = envelope["diagnostics"]
    assert diagnostic["code"] == "Y001"
    assert (diagnostic["line"], diagnostic["col"]) == _place(text, text.index(char))
    assert f"U+{ord(char):04X}" in diagnostic["message"]
    assert "position" not in diagnostic["message"]  # no parser internals
    assert diagnostic["hint"]


def _room_map(folder: Path) -> Path:
    """A map_server map of a walled room, 2 m square at 0.05 m a cell."""
    free = np.zeros((40, 40), dtype=bool)
    free[2:-2, 2:-2] = True
    return write_map(folder, "room", image_from_free(free), resolution=0.05)


def test_a_refused_character_in_a_map_yaml_is_located(tmp_path: Path) -> None:
    path = _room_map(tmp_path)
    text = path.read_text().replace("negate: 0", "negate: 0 \x00")
    path.write_text(text)
    err = io.StringIO()
    code = main(
        ["import-map", str(path), "-o", str(tmp_path / "m.yaml")], out=io.StringIO(), err=err
    )
    assert code == 2
    line, col = _place(text, text.index("\x00"))
    assert err.getvalue().startswith(f"{path}:{line}:{col}: error[M002]: ")
    assert "\n  hint: " in err.getvalue()


def _mutated(path: tuple[str, ...], value: object) -> str:
    data = yaml.safe_load(SPEC)
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return yaml.safe_dump(data)


SCHEMA_CASES = [
    (("robot", "max_speed"), [1]),
    (("robot", "max_speed"), -1),
    (("robot", "start"), [1]),
    (("regions", "home", "rect"), [0, 0, 1]),
    (("regions", "home", "rect"), "wide"),
    (("regions", "hazard"), [[0, 0], [1, 1]]),
    (("name",), 5),
    (("task",), [3]),
    (("version",), 2),
    (("options",), {"cost": "fast"}),
    (("workspace", "boundary"), {"rect": [0, 0, "x", 8]}),
]

YAML_CASES = [
    "version: 1\nname: *nowhere\n",  # an undefined alias
    "version: 1\n---\nversion: 1\n",  # two documents
    "version: 1\nname: " + "[" * 70 + "]" * 70 + "\n",  # too deep
    "version: 1\nname: !!float abc\n",  # a tag that does not read
    "version: 1\n[a, b]: 1\n",  # a key that is not a name
    "version: 1\nname: a\x00\n",  # a refused character
]


@pytest.mark.parametrize("text", [_mutated(p, v) for p, v in SCHEMA_CASES] + YAML_CASES)
def test_every_error_of_a_mission_has_a_hint(tmp_path: Path, text: str) -> None:
    path = tmp_path / "m.yaml"
    path.write_text(text)
    code, envelope = _check(path)
    assert code == 1
    errors = [d for d in envelope["diagnostics"] if d["severity"] == "error"]
    assert errors
    for diagnostic in errors:
        assert diagnostic.get("hint"), diagnostic
        assert diagnostic.get("line"), diagnostic
        assert diagnostic.get("col"), diagnostic


def test_a_schema_hint_says_what_is_asked_and_where() -> None:
    import jsonschema

    from tlmpc.io.schema_check import load_schema

    data = yaml.safe_load(_mutated(("options",), {"cost": "fast"}))
    (problem,) = jsonschema.Draft202012Validator(load_schema("mission")).iter_errors(data)
    from tlmpc.mission.load import _expected

    hint = _expected(problem)
    assert "length, hops, time" in hint
    assert (
        load_schema("mission")["properties"]["options"]["properties"]["cost"]["description"] in hint
    )


def test_a_map_value_that_does_not_read_has_a_hint(tmp_path: Path) -> None:
    path = _room_map(tmp_path)
    text = path.read_text().replace("resolution: 0.05", "resolution: !!float abc")
    path.write_text(text)
    err = io.StringIO()
    argv = ["import-map", str(path), "-o", str(tmp_path / "m.yaml")]
    assert main(argv, out=io.StringIO(), err=err) == 2
    assert "error[M002]" in err.getvalue()
    assert "\n  hint: " in err.getvalue()


@pytest.mark.parametrize("escape", ["\\q", "\\ud83d", "\\udc00", "\\u12", "\\x4", "\\U0011FFFF"])
def test_a_bad_escape_gets_a_hint_about_escapes(tmp_path: Path, escape: str) -> None:
    """The oracle: PyYAML's pure-Python reader refuses the same string (or, for a lone
    surrogate half, reads a string no UTF-8 file can hold)."""
    entry = f'title: "a {escape} b"'
    try:
        yaml.load(entry, Loader=yaml.SafeLoader)["title"].encode("utf-8")
        pytest.fail(f"{escape} is a good escape")
    except (yaml.YAMLError, UnicodeEncodeError, ValueError):
        pass
    text = SPEC.replace("version: 1", f"version: 1\n{entry}", 1)
    path = tmp_path / "mission.yaml"
    path.write_text(text)
    err = io.StringIO()
    assert main(["check", str(path)], io.StringIO(), err) == 1
    first = err.getvalue().splitlines()
    line = text.splitlines().index(entry) + 1
    assert first[0].startswith(f"{path}:{line}:")
    assert "error[Y001]" in first[0]
    assert "escape" in first[1]
