"""Maps a mission cannot hold (M007), and map diagnostics that read well (M004, M006)."""

from __future__ import annotations

import io
import math
from pathlib import Path

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
