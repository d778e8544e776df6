"""Hostile names in every exported text: no forged line, no formula, no invisible control.

Names are drawn from an alphabet of the characters that forge or hide text (newlines, carriage
returns, ANSI escapes, Unicode direction controls and line separators, CSV separators, quotes
and the formula starters ``= + - @``) mixed with plain letters.
"""

from __future__ import annotations

import csv
import io
import json
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import yaml
from hostile_harness import (  # noqa: F401 (fixtures, found by their names)
    FORBIDDEN,
    compiled_fixture,
    compiled_once_fixture,
    room_map_fixture,
    run_hostile,
    work_fixture,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tlmpc.base.errors import error
from tlmpc.io.outputs import plain_name

HOSTILE_CHARS = [
    "\n",
    "\r",
    "\t",
    "\x1b",
    "\x00",
    "\x7f",
    "\x85",
    "\u202e",
    "\u2066",
    "\u200f",
    "\u2028",
    ",",
    ";",
    '"',
    "'",
    "=",
    "+",
    "-",
    "@",
    "#",
    "<",
    "&",
    " ",
    "a",
    "Z",
    "9",
    "é",
]
hostile_text = st.text(alphabet=st.sampled_from(HOSTILE_CHARS), min_size=1, max_size=24)
FEW = settings(
    max_examples=12,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


def _rename(out: Path, name: str) -> None:
    path = out / "mission.json"
    document = json.loads(path.read_text())
    document["name"] = name
    path.write_text(json.dumps(document))


@FEW
@given(name=hostile_text)
def test_waypoints_csv_has_exactly_its_rows(compiled: Path, work: Path, name: str) -> None:
    _rename(compiled, name)
    target = work / "plan.csv"
    result = run_hostile(
        work,
        "export-plan",
        str(compiled),
        "--format",
        "waypoints-csv",
        "-o",
        str(target),
        may_write=["plan.csv"],
    )
    assert result.code == 0, result.err
    text = target.read_text()
    lines = text.split("\n")
    assert lines[-1] == ""
    assert not any(FORBIDDEN.search(line) or "\r" in line for line in lines)
    comments = [line for line in lines[:-1] if line.startswith("#")]
    assert len(comments) == 2  # the mission and the loop start: the name added no line
    rows = list(csv.reader(io.StringIO("\n".join(lines[2:]))))
    assert rows[0] == ["t", "x", "y", "yaw"]
    for row in rows[1:]:
        assert len(row) == 4
        [float(cell) for cell in row]  # numbers only: no injected cell
    # the comment, read as CSV: its first cell, and the name as one neutralised cell
    cells = next(csv.reader(io.StringIO(comments[0])))
    assert cells[0] == "# tlmpc.waypoints/1 mission"
    assert len(cells) == 2
    shown = plain_name(name)
    assert cells[1] == ("'" + shown if shown.startswith(("=", "+", "-", "@", "\t")) else shown)


@FEW
@given(name=hostile_text)
def test_yaml_and_geojson_keep_the_name_exactly(compiled: Path, work: Path, name: str) -> None:
    _rename(compiled, name)
    for fmt, file in (("waypoints-yaml", "plan.yaml"), ("geojson", "plan.geojson")):
        result = run_hostile(
            work, "export-plan", str(compiled), "--format", fmt, "-o", file, may_write=[file]
        )
        assert result.code == 0, result.err
        text = (work / file).read_text()
        assert not FORBIDDEN.search(text)  # escaped by the format, never raw
        if fmt == "waypoints-yaml":
            document = yaml.safe_load(text)
            assert document["mission"] == name
            assert set(document) == {
                "format",
                "mission",
                "task",
                "frame_id",
                "loop_start",
                "waypoints",
            }
        else:
            document = json.loads(text)
            assert document["features"][0]["properties"]["name"] == name


@FEW
@given(name=hostile_text)
def test_plan_svg_is_xml_without_controls(compiled: Path, work: Path, name: str) -> None:
    _rename(compiled, name)
    result = run_hostile(work, "plot", str(compiled), may_write=["out"])
    assert result.code == 0, result.err
    text = (compiled / "plan.svg").read_text()
    ElementTree.fromstring(text)  # valid XML: an ANSI escape in the title broke it
    assert not FORBIDDEN.search(text)


@given(message=hostile_text, hint=hostile_text, file=hostile_text)
def test_a_diagnostic_is_two_lines_whatever_its_text(message: str, hint: str, file: str) -> None:
    text = error("U001", message, hint=hint, file=file, line=3, col=4).format()
    assert text.count("\n") == 1  # the line and its hint: nothing forged
    assert not FORBIDDEN.search(text)
    assert "\r" not in text


def test_frame_and_topic_with_controls_are_refused(compiled: Path, work: Path) -> None:
    for flag, value in (
        ("--frame-id", "map\n# forged"),
        ("--topic", "/plan\u202e"),
        ("--frame-id", ""),
    ):
        result = run_hostile(
            work,
            "export-plan",
            str(compiled),
            "--format",
            "path-mcap",
            "-o",
            "p.mcap",
            flag,
            value,
            located=False,
        )
        assert result.code == 2
        assert result.codes() == ["M084"]
