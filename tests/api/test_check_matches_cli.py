"""`tlmpc.check` reports what `tlmpc check` reports, for a path and for the same YAML text:
the loader's problems and those the command finds after it (a contradictory task, a reactive
part outside GR(1), the body, features finer than the snapping grid), and the notes."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

import tlmpc
from tlmpc.cli import main

HEAD = """\
version: 1
name: case
workspace:
  boundary: {rect: [0, 0, 10, 10]}
"""
CASES = {
    # T011: no behaviour satisfies F a & G !a
    "contradiction": HEAD + "regions:\n  a: {rect: [1, 1, 2, 2]}\nrobot: {start: [5, 5]}\n"
    "task:\n  - visit a\n  - avoid a\n",
    # L020: the `ltl:` alone
    "ltl": HEAD + "regions:\n  a: {rect: [1, 1, 2, 2]}\nrobot: {start: [5, 5]}\n"
    'ltl: "F a & G !a"\n',
    # R001: the body overlaps the wall at the start
    "body": HEAD + "regions:\n  a: {rect: [1, 1, 2, 2]}\n"
    "robot: {start: [0.1, 5], radius: 0.5}\ntask: [visit a]\n",
    # G030: a region thinner than the snapping grid
    "thin": HEAD + "regions:\n  a: {rect: [1, 1, 1.0000000001, 2]}\n"
    "robot: {start: [5, 5]}\ntask: [visit a]\n",
    # Q102: F G outside GR(1) in a reactive mission
    "gr1": HEAD + "regions:\n  a: {rect: [1, 1, 2, 2]}\nsensors: {s: null}\n"
    "robot: {start: [5, 5]}\ntask: [stay in a]\n",
    # G020: a note only (overlapping holes merged); the mission is valid
    "note": HEAD + "  holes: [{rect: [4, 4, 6, 6]}, {rect: [5, 5, 7, 7]}]\n"
    "regions:\n  a: {rect: [1, 1, 2, 2]}\nrobot: {start: [1.5, 8]}\ntask: [visit a]\n",
    # a loader problem, and a valid mission
    "unknown": HEAD + "regions:\n  a: {rect: [1, 1, 2, 2]}\nrobot: {start: [5, 5]}\n"
    "task: [visit a then zz]\n",
    "valid": HEAD + "regions:\n  a: {rect: [1, 1, 2, 2]}\nrobot: {start: [5, 5]}\n"
    "task: [visit a]\n",
}


def _fields(diagnostic: dict[str, object]) -> tuple[object, ...]:
    return tuple(diagnostic.get(k) for k in ("code", "severity", "line", "col", "message", "hint"))


def _cli(path: Path) -> tuple[int, list[tuple[object, ...]]]:
    out = io.StringIO()
    code = main(["check", str(path), "--json"], out=out, err=io.StringIO())
    return code, [_fields(d) for d in json.loads(out.getvalue())["diagnostics"]]


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_api_reports_what_the_command_reports(tmp_path: Path, case: str) -> None:
    path = tmp_path / f"{case}.yaml"
    path.write_text(CASES[case])
    code, expected = _cli(path)
    assert (code == 0) == (case in ("note", "valid"))
    if case != "valid":
        assert expected, "the command found something to report"
    by_path = [_fields(d.to_json()) for d in tlmpc.check(path)]
    by_text = [_fields(d.to_json()) for d in tlmpc.check(CASES[case])]
    assert by_path == expected
    assert by_text == expected


def test_a_map_yaml_is_checked_as_a_map(tmp_path: Path) -> None:
    mission = tmp_path / "site.yaml"
    assert main(["new", "map", "-o", str(mission)], out=io.StringIO(), err=io.StringIO()) == 0
    map_yaml = tmp_path / "site-map.yaml"
    code, expected = _cli(map_yaml)
    assert code == 0
    assert [_fields(d.to_json()) for d in tlmpc.check(map_yaml)] == expected
    assert [d.code for d in tlmpc.check(map_yaml)] == ["M020"]
