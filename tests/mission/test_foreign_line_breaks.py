"""U+0085, U+2028 and U+2029 are line breaks to YAML 1.1 only: a mission or map holding one
is refused at the character, at the line and column an editor shows, instead of being read
with a comment cut short (the rest of the comment's line read as keys) and every later line
number off by one."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.importers.occupancy import read_metadata

BREAKS = ["\x85", "\u2028", "\u2029"]

MISSION = """\
version: 1
name: hidden # a note{char}ltl: G !a
workspace:
  boundary: {{rect: [0, 0, 10, 10]}}
regions:
  a: {{rect: [1, 1, 2, 2]}}
robot: {{start: [5, 5]}}
task:
  - visit a
"""


def _editor_place(text: str, char: str) -> tuple[int, int]:
    """Line and column of ``char`` as an editor counts them (lines end at "\\n" only)."""
    before = text[: text.index(char)]
    return before.count("\n") + 1, len(before) - (before.rfind("\n") + 1) + 1


def _errors(path: Path) -> list[tuple[str, int, int]]:
    out = io.StringIO()
    main(["check", str(path), "--json"], out=out, err=io.StringIO())
    return [
        (d["code"], d["line"], d["col"])
        for d in json.loads(out.getvalue())["diagnostics"]
        if d["severity"] == "error"
    ]


@pytest.mark.parametrize("char", BREAKS)
def test_a_yaml_1_1_line_break_in_a_comment_is_refused_where_the_editor_shows_it(
    tmp_path: Path, char: str
) -> None:
    text = MISSION.format(char=char)
    path = tmp_path / "hidden.yaml"
    path.write_text(text, encoding="utf-8")
    assert _errors(path) == [("Y001", *_editor_place(text, char))]


@pytest.mark.parametrize("char", BREAKS)
def test_one_in_a_json_mission_string_is_refused_at_its_place(tmp_path: Path, char: str) -> None:
    text = (
        '{"version": 1,\n "name": "x' + char + 'y", "workspace": {"boundary": {"rect": [0, 0, '
        '10, 10]}},\n "regions": {"a": {"rect": [1, 1, 2, 2]}}, "robot": {"start": [5, 5]}, '
        '"task": ["visit a"]}\n'
    )
    path = tmp_path / "m.json"
    path.write_text(text, encoding="utf-8")
    assert _errors(path) == [("Y001", *_editor_place(text, char))]
    # written as JSON's escape, the same name is read
    path.write_text(text.replace(char, f"\\u{ord(char):04x}"), encoding="utf-8")
    assert _errors(path) == []


@pytest.mark.parametrize("char", BREAKS)
def test_a_map_yaml_holding_one_is_refused_at_its_place(tmp_path: Path, char: str) -> None:
    text = (
        f"image: room.pgm\nresolution: 0.1 # cells{char}origin: [0, 0, 0]\n"
        "origin: [-1, -1, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    path = tmp_path / "room.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(UsageError) as refused:
        read_metadata(path)
    (found,) = refused.value.diagnostics
    assert (found.code, found.line, found.col) == ("M002", *_editor_place(text, char))
