"""`tlmpc check`: exit codes, --json, --explain, speed-sensitive imports."""

from __future__ import annotations

import io
import json
import subprocess
import sys
from pathlib import Path

import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPECS = sorted(str(p) for p in (ROOT / "specs").glob("*.yaml"))
BAD = Path(__file__).parent / "bad"


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(["check", *argv], out=out, err=err), out.getvalue(), err.getvalue()


def test_specs_are_valid() -> None:
    code, _, err = run(*SPECS)
    assert code == 0, err
    assert f"{len(SPECS)} of {len(SPECS)} mission file(s) valid" in err


def test_explain_prints_the_ltl() -> None:
    code, out, _ = run(str(ROOT / "specs" / "example1.yaml"), "--explain")
    assert code == 0
    assert "F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))" in out


def test_issue_examples_exit_1_with_positions() -> None:
    for name, code_ in [
        ("unknown-top-key", "S001"),
        ("bow-tie", "G004"),
        ("start-in-hole", "G010"),
        ("next-operator", "L004"),
    ]:
        path = BAD / f"{name}.yaml"
        code, _, err = run(str(path))
        assert code == 1
        assert f"{path}:" in err
        assert f"error[{code_}]" in err
        assert "hint:" in err


def test_json_is_one_document_on_stdout() -> None:
    code, out, _ = run(SPECS[0], str(BAD / "bow-tie.yaml"), "--json")
    assert code == 1
    document = json.loads(out)
    assert document["ok"] is False
    files = document["result"]["files"]
    assert [f["ok"] for f in files] == [True, False]
    assert files[1]["diagnostics"][0]["code"] == "G004"
    assert files[0]["ltl"]
    assert document["diagnostics"][0]["code"] == "G004"


def test_unreadable_file_exits_2() -> None:
    code, _, err = run(SPECS[0], "/nonexistent/mission.yaml")
    assert code == 2
    assert "error[U001]" in err


def test_check_imports_no_heavy_packages() -> None:
    script = (
        "import sys, io\n"
        "from tlmpc.cli import main\n"
        f"code = main(['check', {SPECS[0]!r}], io.StringIO(), io.StringIO())\n"
        "heavy = sorted(m for m in sys.modules if m.split('.')[0] in "
        "('scipy', 'cvxpy', 'triangle', 'matplotlib', 'clarabel'))\n"
        "print(code, heavy)\n"
    )
    completed = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert completed.stdout.strip() == "0 []"


def test_check_of_a_plain_mission_imports_no_geometry_or_schema_library() -> None:
    """Example 1 (a rectangle, small polygons, a point robot, task phrases only): the pure
    Python checks answer; shapely, numpy, jsonschema and lark stay unloaded."""
    example1 = str(ROOT / "specs" / "example1.yaml")
    script = (
        "import sys, io\n"
        "from tlmpc.cli import main\n"
        f"code = main(['check', {example1!r}], io.StringIO(), io.StringIO())\n"
        "heavy = sorted(m for m in sys.modules if m.split('.')[0] in "
        "('numpy', 'shapely', 'jsonschema', 'lark'))\n"
        "print(code, heavy)\n"
    )
    completed = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert completed.stdout.strip() == "0 []"


def test_console_entry_point_runs() -> None:
    completed = subprocess.run(
        [sys.executable, "-m", "tlmpc", "check", SPECS[0]],
        capture_output=True,
        text=True,
        check=False,
    )
    assert completed.returncode == 0, completed.stderr


SUBGRID = """version: 1
name: grid
workspace:
  boundary: {rect: [0, 0, 10, 10]}
regions:
  goal: {rect: [8, 1, 9, 9]}
  wall: [[5, 0], [5.000000003, 0], [5.000000003, 10], [5, 10]]
  left: [[2, 2], [3, 2], [3, 3], [2, 3]]
  close: [[3.0000000003, 2], [4, 2], [4, 3], [3.0000000003, 3]]
robot: {start: [1, 5], max_speed: 1.0}
ltl: "F goal"
"""


def test_check_reports_the_subgrid_features_compile_refuses(tmp_path: Path) -> None:
    """G030 (a strip thinner than the grid) and G031 (a gap below it): check gives exactly
    the diagnostics compile gives, at the same lines (compile's are the oracle here, and
    the strip's line is known: the geometry makes these two features sub-grid)."""
    mission = tmp_path / "m.yaml"
    mission.write_text(SUBGRID)
    code, out, _ = run("--json", str(mission))
    assert code == 1
    checked = json.loads(out)["result"]["files"][0]["diagnostics"]
    out_dir = tmp_path / "out"
    compiled_code, compiled_out, _ = run_main("compile", str(mission), "-o", str(out_dir))
    del compiled_out
    assert compiled_code == 1
    assert not out_dir.exists()
    from tlmpc.abstraction import build_abstraction
    from tlmpc.base.errors import InvalidInputError
    from tlmpc.mission import load_mission_text

    try:
        build_abstraction(load_mission_text(SUBGRID, str(mission)))
    except InvalidInputError as refused:
        expected = [d.to_json() for d in refused.diagnostics]
    else:  # pragma: no cover - the oracle must refuse
        raise AssertionError("compile accepted sub-grid features")
    assert checked == expected
    codes = sorted(d["code"] for d in checked)
    assert codes == ["G030", "G031"]
    wall = next(d for d in checked if d["code"] == "G030")
    assert wall["line"] == 7
    assert "'wall'" in wall["message"]
    assert all(d["hint"] for d in checked)


def test_check_of_an_off_grid_mission_without_subgrid_features_passes(tmp_path: Path) -> None:
    """Coordinates off the grid but features wide enough: the shapely check runs, finds
    nothing, and the mission is valid."""
    mission = tmp_path / "m.yaml"
    mission.write_text(
        SUBGRID.replace("5.000000003", "5.3")
        .replace("3.0000000003", "3.3")
        .replace("[8, 1, 9, 9]", "[8.00000000001, 1, 9, 9]")
    )
    code, _, err = run(str(mission))
    assert code == 0, err


def run_main(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


# --- positions inside task phrases and formulas written over several YAML lines ---------------

POSITIONED = """\
version: 1
name: positions
workspace: {boundary: {rect: [0, 0, 10, 10]}}
regions:
  a: {rect: [1, 1, 2, 2]}
  b: {rect: [4, 1, 5, 2]}
  c: {rect: [7, 1, 8, 2]}
robot: {start: [0.5, 0.5], max_speed: 1.0}
"""

#: (the task as written, the code, a piece of the raw text that occurs once, and where in that
#: piece the diagnostic must point): every YAML form a phrase or a formula can take.
LAYOUTS = [
    (
        "folded",
        "task:\n  - >-\n    visit a then b\n    while avoiding b\n",
        "T010",
        "avoiding b",
        9,
    ),
    ("plain", "task:\n  - visit a then\n    b while avoiding qq\n", "L010", "qq", 0),
    ("single", "task:\n  - 'visit a then\n    b while avoiding b'\n", "T010", "avoiding b", 9),
    (
        "double",
        'task:\n  - "visit a then \\\n    c while avoiding c"\n',
        "T010",
        "avoiding c",
        9,
    ),
    ("literal", "task:\n  - |\n    visit a then\n    b while avoiding zz\n", "L010", "zz", 0),
    ("literal-one-line", "task:\n  - |-\n    visit a then b while avoiding zz\n", "L010", "zz", 0),
    ("ltl-literal", "ltl: |\n  F a &\n    G !zz\n", "L010", "zz", 0),
    ("ltl-folded", "ltl: >-\n  F a &\n   G (b | zz)\n", "L010", "zz", 0),
    ("ltl-plain", "ltl: F a\n  & G !zz\n", "L010", "zz", 0),
    # a phrase that does not parse: where the parser stopped
    ("t001-folded", "task:\n  - >-\n    visit a then\n    b qq\n", "T001", "qq", 0),
    ("t001-literal", "task:\n  - |\n    visit a then\n    b qq\n", "T001", "qq", 0),
    ("t001-plain", "task:\n  - visit a then\n    b qq\n", "T001", "qq", 0),
    ("ltl-single", "ltl: 'F a &\n\n     G !zz'\n", "L010", "zz", 0),
    ("ltl-double", 'ltl: "F a & \\\n     G !\\"zz\\""\n', "L010", '\\"zz', 0),
    ("ltl-syntax", "ltl: |\n  F a &\n    G $ b\n", "L001", "$", 0),
    ("ltl-next", "ltl: >\n  F a &\n    X b\n", "L004", "X", 0),
    ("ltl-ends-early", "ltl: |\n  F (a &\n    b\n", "L002", "    b\n", 5),
    ("ltl-doubled-quote", "ltl: 'F \"it''s\" &\n   G !zz'\n", "L010", "zz", 0),
    # a file with Windows line ends (the whole mission is written with them)
    (
        "crlf-literal",
        "task:\r\n  - |\r\n    visit a then\r\n    b while avoiding zz\r\n",
        "L010",
        "zz",
        0,
    ),
    (
        "crlf-double",
        'task:\r\n  - "visit a then \\\r\n    c while avoiding zz"\r\n',
        "L010",
        "zz",
        0,
    ),
]


def _expected(text: str, piece: str, offset: int) -> tuple[int, int]:
    """The 1-based line and column of ``piece`` (which occurs once) plus ``offset``."""
    assert text.count(piece) == 1, piece
    index = text.index(piece) + offset
    return text.count("\n", 0, index) + 1, index - (text.rfind("\n", 0, index) + 1) + 1


@pytest.mark.parametrize("command", ["check", "compile"])
@pytest.mark.parametrize(
    ("task", "code_", "piece", "offset"),
    [case[1:] for case in LAYOUTS],
    ids=[case[0] for case in LAYOUTS],
)
def test_positions_in_strings_over_several_yaml_lines(
    tmp_path: Path, command: str, task: str, code_: str, piece: str, offset: int
) -> None:
    mission = tmp_path / "m.yaml"
    text = POSITIONED.replace("\n", "\r\n") + task if "\r" in task else POSITIONED + task
    mission.write_bytes(text.encode("utf-8"))
    argv = [command, str(mission)] + (["-o", str(tmp_path / "out")] if command == "compile" else [])
    code, _, err = run_main(*argv)
    assert code == 1, err
    line, col = _expected(text, piece, offset)
    assert f"{mission}:{line}:{col}: error[{code_}]" in err, err


# --- values that pass the schema but that the compiler's later stages cannot carry -------------

SLOW = """\
version: 1
name: slow
workspace: {boundary: {rect: [0, 0, 12, 8]}}
regions:
  home: {rect: [0.5, 0.5, 2.0, 2.0]}
  dock: {rect: [10.0, 6.0, 11.5, 7.5]}
robot: {start: [1.0, 1.0], max_speed: SPEED}
task:
  - avoid home
  - PHRASE
"""


@pytest.mark.parametrize("command", ["check", "compile"])
@pytest.mark.parametrize("speed", ["1.0e-12", "1.0e-320", "1.4e-11"])
def test_a_max_speed_too_small_to_cross_the_workspace_is_refused(
    tmp_path: Path, command: str, speed: str
) -> None:
    # 14.42 across (the rectangle's diagonal) at under 1.442e-11 takes more than 1e12 s; compile
    # used to fail at exit 3 (C010, C031) or exit 2 with a V024 about its own trace
    mission = tmp_path / "m.yaml"
    mission.write_text(SLOW.replace("SPEED", speed).replace("PHRASE", "visit dock"))
    argv = [command, str(mission)] + (["-o", str(tmp_path / "out")] if command == "compile" else [])
    code, _, err = run_main(*argv)
    assert code == 1, err
    assert err.startswith(f"{mission}:7:39: error[S010]: $.robot.max_speed: "), err
    assert "hint: give a max_speed of at least 1.44e-11" in err
    assert not (tmp_path / "out").exists()


def test_a_max_speed_just_fast_enough_is_valid(tmp_path: Path) -> None:
    mission = tmp_path / "m.yaml"
    mission.write_text(SLOW.replace("SPEED", "1.5e-11").replace("PHRASE", "visit dock"))
    assert run_main("check", str(mission))[0] == 0


@pytest.mark.parametrize("command", ["check", "compile"])
def test_a_then_chain_nested_beyond_the_readers_limit_is_refused_at_its_phrase(
    tmp_path: Path, command: str
) -> None:
    # 200 `then`s nest 402 levels (403 in the conjunction with `avoid home`), more than the
    # LTL reader's 400 (L005): compile used to
    # spend a minute in the automaton stage, then fail at <input>:1:1 with exit 2
    mission = tmp_path / "m.yaml"
    chain = "visit dock then " * 200 + "visit home"
    mission.write_text(SLOW.replace("SPEED", "1.0").replace("PHRASE", chain))
    argv = [command, str(mission)] + (["-o", str(tmp_path / "out")] if command == "compile" else [])
    code, _, err = run_main(*argv)
    assert code == 1, err
    assert err.startswith(
        f"{mission}:10:5: error[L005]: the LTL formula is nested more than 400 levels deep "
        "(403 with task phrase 2)"
    ), err
    assert not (tmp_path / "out").exists()
    # one `then` fewer: 401 levels with the conjunction, refused at the same phrase
    mission.write_text(SLOW.replace("SPEED", "1.0").replace("PHRASE", chain[16:]))
    assert f"{mission}:10:5: error[L005]" in run_main("check", str(mission))[2]
    # 198 `then`s: 399 levels, within the limit
    mission.write_text(SLOW.replace("SPEED", "1.0").replace("PHRASE", chain[32:]))
    assert run_main("check", str(mission))[0] == 0
