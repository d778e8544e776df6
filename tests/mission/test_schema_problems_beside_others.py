"""A schema problem hides only what it makes meaningless (docs/mission-format.md): the geometry
of the shape it refuses, and the task when a name the task may use was refused.  Every other
problem of the file is reported beside it, each as it is reported alone, by `tlmpc check` and
`tlmpc compile --until load` alike; and no value the schema refused reaches a later check
(mutated shipped missions never make the loader fail)."""

from __future__ import annotations

import io
import json
import random
from pathlib import Path
from typing import Any

import pytest
import yaml

from tlmpc.cli import main
from tlmpc.mission import check_text

ROOT = Path(__file__).resolve().parents[2]

# three independent problems: a hole with xmin > xmax (G001, line 5), a negative speed (S010,
# line 9) and a task naming no region (L010, line 11)
THREE = """\
version: 1
name: skip
workspace:
  boundary: {rect: [0, 0, 10, 10]}
  holes: [{rect: [5, 5, 4, 6]}]
regions:
  a: {rect: [1, 1, 2, 2]}

robot: {start: [5, 5], max_speed: -1}
task:
  - visit a then zz
"""

FIXES = {  # each problem's fix, as text replaced
    "G001": ("[5, 5, 4, 6]", "[6, 6, 7, 7]"),
    "S010": ("max_speed: -1", "max_speed: 1"),
    "L010": ("a then zz", "a then a"),
}


def _errors(text: str) -> set[tuple[str, int | None, int | None, str]]:
    return {(d.code, d.line, d.col, d.message) for d in check_text(text, "m.yaml")}


def _alone(code: str) -> str:
    """THREE with every problem but ``code`` fixed."""
    text = THREE
    for other, (bad, good) in FIXES.items():
        if other != code:
            text = text.replace(bad, good)
    return text


def test_each_problem_is_reported_beside_the_others_as_it_is_alone() -> None:
    found = _errors(THREE)
    assert {(code, line, col) for code, line, col, _ in found} == {
        ("G001", 5, 11),
        ("S010", 9, 35),
        ("L010", 11, 18),
    }
    for code in FIXES:
        alone = _errors(_alone(code))
        assert {d[0] for d in alone} == {code}
        assert alone <= found


MISSION = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 10]}
  holes: [HOLES]
regions:
  a: {rect: [1, 1, 2, 2]}
  out: {rect: [9, 9, 12, 12]}
groups: {g: [a]}
robot: {start: [5, 5]}
task: [visit all g]
"""


def _codes(text: str) -> list[tuple[str, int | None]]:
    return sorted((d.code, d.line) for d in check_text(text, "m.yaml"))


def test_a_shape_the_schema_refused_is_not_measured_but_the_others_are() -> None:
    text = MISSION.replace("HOLES", "{rect: [5, 5, 4]}, {rect: [5, 5, 4, 6]}")
    # the refused hole (three numbers, S009) has no geometry problem; the other one's G001,
    # and the region outside the boundary (G007), are found
    assert _codes(text) == [("G001", 4), ("G007", 7), ("S009", 4)]
    (refused,) = [d for d in check_text(text, "m.yaml") if d.code == "S009"]
    assert refused.path == "$.workspace.holes[0].rect"


@pytest.mark.parametrize(
    ("broken", "code"),
    [
        ("groups: {g: [a, 5]}", "S005"),  # a member that is no name
        ("groups: {g: [a, F]}", "S008"),  # an LTL keyword
        ("groups: [a]", "S005"),  # no mapping
    ],
)
def test_a_refused_declaration_makes_no_false_unknown_name(broken: str, code: str) -> None:
    text = MISSION.replace("HOLES", "").replace("groups: {g: [a]}", broken)
    found = _codes(text)
    # the task names `g`, refused with the groups: no L010 or T0xx for it, only the schema's
    # problem and the geometry (the region outside the boundary)
    assert [c for c, _ in found] == sorted([code, "G007"])


def test_a_robot_without_start_still_has_its_regions_checked() -> None:
    text = MISSION.replace("HOLES", "").replace("robot: {start: [5, 5]}", "robot: {radius: -1}")
    assert _codes(text) == [("G007", 7), ("S002", 9), ("S010", 9)]


def test_a_component_without_boundary_is_told_once_and_the_rest_checked() -> None:
    text = MISSION.replace("HOLES", "").replace(
        "  holes: []", "  components: [{holes: [{rect: [21, 1, 22, 2]}]}]\n  holes: []"
    )
    # the component's missing boundary (the schema's S002) leaves its hole unread; the region
    # outside the main boundary is still found
    assert _codes(text) == [("G007", 8), ("S002", 4)]


@pytest.mark.parametrize("workspace", ["", "workspace: 5\n"])
def test_a_workspace_missing_or_refused_is_told_once(workspace: str) -> None:
    text = MISSION.replace("HOLES", "")
    text = text.replace("workspace:\n  boundary: {rect: [0, 0, 10, 10]}\n  holes: []\n", workspace)
    found = check_text(text, "m.yaml")
    assert [d.code for d in found] == ["S002" if not workspace else "S005"]
    assert found[0].path == ("$.workspace" if workspace else "$")


def test_a_map_workspace_is_not_read_beside_schema_problems(tmp_path: Path) -> None:
    text = (ROOT / "tlmpc" / "templates" / "map.yaml").read_text()
    text = text.replace("max_speed: 0.5", "max_speed: -0.5")
    # the map file does not exist here: with a schema problem the map is not read (no M0xx)
    assert [d.code for d in check_text(text, str(tmp_path / "m.yaml"))] == ["S010"]


def _json_errors(argv: list[str]) -> list[tuple[Any, ...]]:
    out = io.StringIO()
    main([*argv, "--json"], out=out, err=io.StringIO())
    return [
        (d["code"], d["line"], d["col"], d["message"], d.get("hint"))
        for d in json.loads(out.getvalue())["diagnostics"]
        if d["severity"] == "error"
    ]


@pytest.mark.parametrize(
    "text",
    [
        THREE,
        MISSION.replace("HOLES", "{rect: [5, 5, 4]}, {rect: [5, 5, 4, 6]}"),
        MISSION.replace("HOLES", "").replace("robot: {start: [5, 5]}", "robot: {radius: -1}"),
    ],
)
def test_check_and_compile_report_the_same(tmp_path: Path, text: str) -> None:
    path = tmp_path / "m.yaml"
    path.write_text(text)
    checked = _json_errors(["check", str(path)])
    compiled = _json_errors(["compile", str(path), "-o", str(tmp_path / "out"), "--until", "load"])
    assert len(checked) >= 2
    assert checked == compiled


SEEDS = [
    "specs/example1.yaml",
    "specs/deadline.yaml",
    "specs/patrol.yaml",
    "specs/reach-avoid.yaml",
    "specs/reactive/guard.yaml",
    "tlmpc/templates/reach-avoid.yaml",
]
#: values of another type or out of range, put in place of one value of a mission
REPLACEMENTS: list[Any] = ["x", -1, 0, True, None, [], {}, [[1, 2]], "F", {"a": 1}]
#: mutants per seed mission (the test's budget)
BUDGET = 60


def _paths(value: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    found = [path] if path else []
    if isinstance(value, dict):
        for key, item in value.items():
            found += _paths(item, (*path, key))
    elif isinstance(value, list) and len(value) <= 8:
        for index, item in enumerate(value):
            found += _paths(item, (*path, index))
    return found


@pytest.mark.parametrize("seed", SEEDS)
def test_mutated_missions_never_fail_and_keep_an_unrelated_problem(seed: str) -> None:
    original = yaml.safe_load((ROOT / seed).read_text())
    draw = random.Random(seed)
    paths = [p for p in _paths(original) if p[:2] != ("workspace", "holes")]
    for _ in range(BUDGET):
        data = json.loads(json.dumps(original))
        path = draw.choice(paths)
        parent = data
        for key in path[:-1]:
            parent = parent[key]
        if draw.random() < 0.3:
            del parent[path[-1]]
        else:
            parent[path[-1]] = draw.choice(REPLACEMENTS)
        workspace = data.get("workspace")
        unrelated = isinstance(workspace, dict) and isinstance(workspace.get("boundary"), list)
        if unrelated:
            # a hole with xmin > xmax: G001 whatever the schema finds elsewhere
            workspace["holes"] = [*workspace.get("holes", []), {"rect": [5, 5, 4, 6]}]
        text = yaml.safe_dump(data, sort_keys=False)
        found = check_text(text, "m.yaml")  # never raises
        assert all(d.line is not None for d in found), (path, found)
        if unrelated and not any(d.code.startswith("Y") for d in found):
            assert any(d.code == "G001" for d in found), (path, text, found)
