"""Diagnostics that later stages locate by a JSON path get the line and column of the value."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.base.errors import Diagnostic, InvalidInputError, error
from tlmpc.mission.placement import parse_json_path, placed
from tlmpc.mission.yamlpos import json_path
from tlmpc.pipeline.stages import compile_mission

MISSION = """\
version: 1
name: placed
workspace:
  boundary: {rect: [0, 0, 10, 10]}
regions:
  a: {rect: [1, 1, 3, 3]}
robot:
  start: [5, 5]
  max_speed: 1.0
  disturbance:   0.75
task:
  - visit a
"""


def _value_position(text: str, key: str) -> tuple[int, int]:
    """Where the value after ``key:`` starts, found by reading the lines (not by YAML)."""
    for number, line in enumerate(text.splitlines(), start=1):
        head, sep, rest = line.partition(f"{key}:")
        if sep:
            return number, len(head) + len(sep) + (len(rest) - len(rest.lstrip())) + 1
    raise AssertionError(key)


# any key a YAML mapping may hold: dots, brackets, quotes and spaces are written ["..."]
keys = st.text(min_size=1, max_size=8)


@given(st.lists(st.one_of(keys, st.integers(min_value=0, max_value=999)), max_size=6))
def test_json_paths_read_back(path: list[str | int]) -> None:
    assert parse_json_path(json_path(tuple(path))) == tuple(path)


@pytest.mark.parametrize("text", ["", "robot.disturbance", "$robot", "$.a[x]", "$.a..b"])
def test_text_that_is_no_json_path(text: str) -> None:
    assert parse_json_path(text) is None


def test_a_path_gets_the_position_of_its_value(tmp_path: Path) -> None:
    source = tmp_path / "m.yaml"
    source.write_text(MISSION, encoding="utf-8")
    name = str(source)
    other = error("U001", "elsewhere", file="other.yaml", path="$.robot.disturbance")
    located = error("Y003", "already placed", file=name, line=2, col=3, path="$.name")
    found = placed(
        [error("C032", "too sharp", file=name, path="$.robot.disturbance"), other, located],
        name,
    )
    assert (found[0].line, found[0].col) == _value_position(MISSION, "disturbance")
    assert found[1:] == (other, located)


def test_an_absent_value_is_placed_at_its_nearest_written_ancestor(tmp_path: Path) -> None:
    source = tmp_path / "m.yaml"
    source.write_text(MISSION, encoding="utf-8")
    (diagnostic,) = placed(
        [error("A040", "x", file=str(source), path="$.options.goal_depth")], str(source)
    )
    assert diagnostic.line is None or diagnostic.line >= 1  # no options: the document itself


def test_an_unreadable_source_leaves_the_diagnostics_as_they_were(tmp_path: Path) -> None:
    missing = str(tmp_path / "gone.yaml")
    diagnostics = (error("C032", "x", file=missing, path="$.robot.disturbance"),)
    assert placed(diagnostics, missing) == diagnostics


def test_a_disturbance_too_large_for_any_cell_is_refused_at_its_value(tmp_path: Path) -> None:
    source = tmp_path / "m.yaml"
    source.write_text(MISSION, encoding="utf-8")
    with pytest.raises(InvalidInputError) as caught:
        compile_mission(source)
    refused: list[Diagnostic] = [d for d in caught.value.diagnostics if d.code == "C032"]
    assert refused
    for diagnostic in refused:
        assert (diagnostic.line, diagnostic.col) == _value_position(MISSION, "disturbance")
        assert diagnostic.format().startswith(f"{source}:10:18: error[C032]")


def test_warnings_of_later_stages_are_placed_too(tmp_path: Path) -> None:
    example = (Path(__file__).parent.parent / "specs" / "example1.yaml").read_text(encoding="utf-8")
    text = example.replace("max_speed: 1.0}", "max_speed: 1.0, disturbance: 0.37}")
    assert text != example
    source = tmp_path / "example1.yaml"
    source.write_text(text, encoding="utf-8")
    result = compile_mission(source, until="plan")
    (yielded,) = [w for w in result.warnings if w.code == "A040"]
    assert (yielded.line, yielded.col) == _value_position(text, "disturbance")
