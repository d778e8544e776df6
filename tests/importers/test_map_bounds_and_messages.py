"""Maps a mission cannot hold (M007), and map diagnostics that read well (M004, M006)."""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from robot_data import image_from_free, write_map

from tlmpc.cli import main
from tlmpc.io.schema_check import MISSION_COORDINATE_LIMIT, load_schema
from tlmpc.mission.load import check_file

LIMIT = MISSION_COORDINATE_LIMIT
CELLS = 10


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


def test_the_limit_is_the_mission_schemas() -> None:
    coordinate = load_schema("mission")["$defs"]["coordinate"]
    assert (coordinate["minimum"], coordinate["maximum"]) == (-LIMIT, LIMIT)


def _free_map(tmp_path: Path, resolution: float, origin: tuple[float, float, float]) -> Path:
    free = np.ones((CELLS, CELLS), dtype=bool)
    return write_map(tmp_path, "m", image_from_free(free), resolution=resolution, origin=origin)


def _line_of(path: Path, key: str) -> int:
    lines = path.read_text().splitlines()
    return next(i for i, line in enumerate(lines, 1) if line.startswith(f"{key}:"))


# A map of CELLS free cells a side reaching just past the limit: by its origin, by its cells,
# on the negative side, and turned by its yaw so that only the rotated corner is beyond.
BEYOND = [
    pytest.param(LIMIT / CELLS, (LIMIT * 1e-9, 0.0, 0.0), "resolution", id="cells"),
    pytest.param(1.0, (LIMIT * 1.5, 0.0, 0.0), "origin", id="origin"),
    pytest.param(LIMIT / CELLS, (-1.0, 0.0, math.pi), "resolution", id="yaw"),
]


@pytest.mark.parametrize(("resolution", "origin", "blamed"), BEYOND)
def test_import_map_refuses_coordinates_check_would_reject(
    tmp_path: Path, resolution: float, origin: tuple[float, float, float], blamed: str
) -> None:
    path = _free_map(tmp_path, resolution, origin)
    out = tmp_path / "mission.yaml"
    code, _, err = run("import-map", str(path), "-o", str(out))
    assert code == 2, err
    assert f"{path}:{_line_of(path, blamed)}:" in err
    assert "error[M007]" in err
    assert f"{LIMIT:g}" in err
    assert "hint:" in err
    assert "Traceback" not in err
    assert not out.exists()


def test_a_map_reaching_exactly_the_limit_is_imported_and_checks(tmp_path: Path) -> None:
    path = _free_map(tmp_path, LIMIT / CELLS, (0.0, 0.0, 0.0))
    out = tmp_path / "mission.yaml"
    cell = LIMIT / CELLS
    code, _, err = run(
        "import-map",
        str(path),
        "--region",
        "goal",
        *(str(v) for v in (cell, cell, 2 * cell, 2 * cell)),
        "--task",
        "visit goal",
        "-o",
        str(out),
    )
    assert code == 0, err
    assert check_file(out) == []
    assert f"{LIMIT!r}" in out.read_text()  # the far corner, exactly at the limit


def test_a_mission_loading_such_a_map_says_the_same(tmp_path: Path) -> None:
    path = _free_map(tmp_path, 2 * LIMIT / CELLS, (0.0, 0.0, 0.0))
    mission = tmp_path / "mission.yaml"
    inside = LIMIT / 4
    mission.write_text(
        f"version: 1\nworkspace: {{map: {path.name}}}\n"
        f"regions:\n  goal: {{rect: [{inside}, {inside}, {2 * inside}, {2 * inside}]}}\n"
        f"robot: {{start: [{inside / 2}, {inside / 2}]}}\ntask: [visit goal]\n"
    )
    problems = check_file(mission)
    assert [p.code for p in problems] == ["M007"]
    (problem,) = problems
    assert (problem.file, problem.line) == (str(mission), 2)
    assert f"{path}:{_line_of(path, 'resolution')}:" in problem.message
    assert problem.hint


# --- the map image cannot be decoded (M006) -------------------------------------------------


@pytest.mark.parametrize(
    ("image", "reason"),
    [
        pytest.param(b"P5\n-3 3\n255\n" + bytes(9), "header is malformed", id="negative size"),
        pytest.param(
            b"P5\n3 3\n0\n" + bytes(9),
            "maxval must be greater than 0 and less than 65536",
            id="maxval 0",
        ),
    ],
)
def test_an_undecodable_image_gets_its_whole_reason_and_a_hint(
    tmp_path: Path, image: bytes, reason: str
) -> None:
    path = _free_map(tmp_path, 0.1, (0.0, 0.0, 0.0))
    (tmp_path / "m.pgm").write_bytes(image)
    code, _, err = run("import-map", str(path), "-o", str(tmp_path / "out.yaml"))
    assert code == 2, err
    message, _, hint = err.partition("\n  hint: ")
    assert "error[M006]" in message
    assert reason in message
    assert "..." not in message  # the reason is not cut
    assert "<" not in message  # nor an object's repr
    assert "PGM" in hint


# --- a resolution that is text (M004) ---------------------------------------------------------


@pytest.mark.parametrize(
    ("written", "suggested", "wrong"),
    [
        ('"0.05"', "resolution: 0.05", "exponent"),
        ("'1e-3'", "resolution: 0.001", "exponent"),
        ('"1e-12"', "resolution: 1.0e-12", "exponent"),
        ("1e-3", "1.0e-3", "quotes"),
    ],
)
def test_a_resolution_that_is_text_gets_a_hint_that_fits(
    tmp_path: Path, written: str, suggested: str, wrong: str
) -> None:
    path = _free_map(tmp_path, 0.1, (0.0, 0.0, 0.0))
    text = path.read_text().replace("resolution: 0.1", f"resolution: {written}")
    path.write_text(text)
    code, _, err = run("import-map", str(path), "-o", str(tmp_path / "out.yaml"))
    assert code == 2, err
    message, _, hint = err.partition("\n  hint: ")
    assert f"{path}:{_line_of(path, 'resolution')}:13: error[M004]" in message
    assert suggested in hint
    assert wrong not in hint


# --- every map-YAML diagnostic is located and has a hint (M002-M006, M013) ------------------

GOOD_MAP = (
    "# a map_server map\nimage: m.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
    "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
)


def _written_at(text: str, key: str) -> tuple[int, int]:
    """Where ``key: VALUE`` writes its value (one space after the colon), 1-based."""
    for number, line in enumerate(text.splitlines(), 1):
        if line.startswith(f"{key}:"):
            return number, len(key) + 3
    raise AssertionError(f"{key} is not in the map")


def _without(key: str) -> str:
    return "".join(f"{line}\n" for line in GOOD_MAP.splitlines() if not line.startswith(f"{key}:"))


# (the map's text, the code, the key whose value is blamed, or None: the mapping, at its first key)
DEFECTS = [
    pytest.param(_without("origin"), "M003", None, id="no origin"),
    pytest.param(_without("image"), "M003", None, id="no image"),
    pytest.param(_without("resolution"), "M003", None, id="no resolution"),
    pytest.param(_without("occupied_thresh"), "M003", None, id="no occupied_thresh"),
    pytest.param(_without("free_thresh"), "M003", None, id="no free_thresh"),
    pytest.param(GOOD_MAP.replace("[0.0, 0.0, 0.0]", "~"), "M003", "origin", id="origin null"),
    pytest.param(GOOD_MAP.replace("0.0, 0.0, 0.0", "0.0, 0.0"), "M004", "origin", id="origin"),
    pytest.param(GOOD_MAP.replace("image: m.pgm", "image: 5"), "M004", "image", id="image 5"),
    pytest.param(GOOD_MAP.replace("0.1\n", "0.0\n"), "M004", "resolution", id="resolution 0"),
    pytest.param(GOOD_MAP.replace("negate: 0", "negate: 2"), "M004", "negate", id="negate 2"),
    pytest.param(GOOD_MAP + "mode: fancy\n", "M004", "mode", id="mode"),
    pytest.param(
        GOOD_MAP.replace("0.65", "0.1").replace("0.196", "0.9"),
        "M004",
        "free_thresh",
        id="thresholds swapped",
    ),
    pytest.param(GOOD_MAP.replace("0.65", "1.5"), "M004", "occupied_thresh", id="occupied 1.5"),
    pytest.param(GOOD_MAP.replace("0.196", "-0.1"), "M004", "free_thresh", id="free -0.1"),
    pytest.param(GOOD_MAP.replace("0.65", "high"), "M004", "occupied_thresh", id="occupied text"),
    pytest.param(GOOD_MAP.replace("m.pgm", "gone.pgm"), "M005", "image", id="no image file"),
    pytest.param("# a list\n- image\n- m.pgm\n", "M002", None, id="not a mapping"),
]


@pytest.mark.parametrize(("text", "code", "key"), DEFECTS)
def test_a_map_yaml_diagnostic_is_located_and_has_a_hint(
    tmp_path: Path, text: str, code: str, key: str | None
) -> None:
    path = _free_map(tmp_path, 0.1, (0.0, 0.0, 0.0))
    path.write_text(text)
    line, col = (2, 1) if key is None else _written_at(text, key)  # line 1 is a comment
    code_, _, err = run("import-map", str(path), "-o", str(tmp_path / "out.yaml"))
    assert code_ == 2, err
    assert err.startswith(f"{path}:{line}:{col}: error[{code}]: "), err
    message, _, hint = err.partition("\n  hint: ")
    assert hint.strip(), err
    assert "None" not in message


@pytest.mark.parametrize(
    ("text", "place", "hint"),
    [
        pytest.param(
            GOOD_MAP.replace("0.0, 0.0]", "0.0, 0.0"), (5, 7), "brackets", id="unclosed list"
        ),
        pytest.param(GOOD_MAP + "  extra: 1\n", (8, 8), "indentation", id="indented key"),
        pytest.param(GOOD_MAP + "\tmode: trinary\n", (8, 1), "tabs", id="tab"),
    ],
)
def test_a_map_yaml_syntax_error_is_located_and_has_a_hint(
    tmp_path: Path, text: str, place: tuple[int, int], hint: str
) -> None:
    path = _free_map(tmp_path, 0.1, (0.0, 0.0, 0.0))
    path.write_text(text)
    code_, _, err = run("import-map", str(path), "-o", str(tmp_path / "out.yaml"))
    assert code_ == 2, err
    line, col = place
    assert err.startswith(f"{path}:{line}:{col}: error[M002]: YAML syntax error: "), err
    assert hint in err.partition("\n  hint: ")[2], err


@pytest.mark.parametrize(
    ("change", "key"),
    [
        (lambda t: t.replace("resolution: 0.1", "resolution: 0.2"), "resolution"),
        (lambda t: t.replace("[0.0, 0.0, 0.0]", "[1.0, 0.0, 0.0]"), "origin"),
    ],
)
def test_a_mask_that_does_not_fit_the_map_is_refused_at_its_key(
    tmp_path: Path, change: Any, key: str
) -> None:
    path = _free_map(tmp_path, 0.1, (0.0, 0.0, 0.0))
    mask = write_map(tmp_path, "k", image_from_free(np.ones((CELLS, CELLS), dtype=bool)))
    mask.write_text(change(mask.read_text()))
    code, _, err = run("import-map", str(path), "--keepout", str(mask))
    assert code == 2, err
    assert err.startswith(f"{mask}:{_line_of(mask, key)}:"), err
    assert "error[M013]" in err
    assert "\n  hint: " in err


def test_free_space_lost_in_simplification_is_blamed_on_the_map_with_a_hint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The simplified coverage keeps the exact faces' area by construction; should it ever
    come back empty, M011 names the map and says what to change."""
    from tlmpc.importers import maps

    def nothing_left(*_: object) -> tuple[list[object], dict[int, list[object]]]:
        return [], {}

    monkeypatch.setattr(maps, "_coverage", nothing_left)
    path = _free_map(tmp_path, 0.1, (0.0, 0.0, 0.0))
    code, _, err = run("import-map", str(path), "-o", str(tmp_path / "out.yaml"))
    assert code == 2, err
    assert err.startswith(f"{path}: error[M011]: "), err
    assert "--tolerance" in err.partition("\n  hint: ")[2], err
    assert not (tmp_path / "out.yaml").exists()
