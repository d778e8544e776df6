"""The input policy: devices and FIFOs, alias bombs, image bombs, non-finite settings, maps
that would take minutes; each a located diagnostic, nothing written."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest
import yaml
from hostile_harness import (  # noqa: F401 (fixtures, found by their names)
    MAP_YAML,
    compiled_fixture,
    compiled_once_fixture,
    room_map_fixture,
    run_hostile,
    work_fixture,
    write_map,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tlmpc.importers import maps

ROOT = Path(__file__).resolve().parents[2]

MISSION = """\
version: 1
name: m
workspace:
  map: {map}
regions:
  a: [[0.3, 0.3], [0.8, 0.3], [0.8, 0.8], [0.3, 0.8]]
robot:
  start: [1.5, 1.5]
  max_speed: 1.0
task:
  - visit a
"""


@pytest.fixture
def fifo(work: Path) -> Path:
    """A FIFO without a writer: a reader that opens it the usual way blocks forever."""
    path = work / "pipe.yaml"
    os.mkfifo(path)
    return path


def _guarded(*argv: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    """``tlmpc ARGV`` in a child, so a regression (a read that blocks) cannot take the test
    process with it.  No clock of ours decides a verdict: such a regression hangs this child,
    and the CI job's own limit stops it."""
    return subprocess.run(
        [sys.executable, "-m", "tlmpc", *argv],
        cwd=cwd,
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )


@pytest.mark.parametrize("special", ["/dev/zero", "FIFO"])
def test_devices_and_fifos_are_refused_by_every_reader(
    work: Path, fifo: Path, compiled: Path, room_map: Path, special: str
) -> None:
    path = str(fifo) if special == "FIFO" else special
    csv_log = work / "log.csv"  # the CSV reader's turn: a FIFO, or a link to the device
    if special == "FIFO":
        os.mkfifo(csv_log)
    else:
        csv_log.symlink_to(special)
    (work / "mission.yaml").write_text(MISSION.format(map=path))
    (work / "masked.yaml").write_text(MISSION.format(map=room_map))
    cases = [
        (["check", "mission.yaml"], "M001"),
        (["check", path], "U001"),
        (["import-map", path], "M001"),
        (["import-map", str(room_map), "--keepout", path], "M001"),
        (["verify", path, "--mission", "masked.yaml"], "U001"),  # read as a trace.json
        (["verify", "log.csv", "--mission", "masked.yaml"], "M050"),
    ]
    for argv, code in cases:
        done = _guarded(*argv, cwd=work)
        assert done.returncode in (1, 2), done.stderr
        assert "Traceback" not in done.stderr
        if code is not None:
            assert f"error[{code}]" in done.stderr, (argv, done.stderr)
    # an artifact swapped for a FIFO
    (compiled / "trace.json").unlink()
    os.mkfifo(compiled / "trace.json")
    done = _guarded("export-plan", "out", cwd=work)
    assert done.returncode == 2
    assert "error[U041]" in done.stderr
    assert "not a regular file" in done.stderr


def test_an_image_that_is_a_fifo_is_refused(work: Path, fifo: Path) -> None:
    (work / "map.yaml").write_text(MAP_YAML.format(image=fifo.name))
    done = _guarded("import-map", "map.yaml", cwd=work)
    assert done.returncode == 2
    assert "error[M006]" in done.stderr
    assert "FIFO" in done.stderr


def _alias_bomb(levels: int, width: int) -> str:
    lines = ["a0: &a0 [" + ", ".join(["1.0"] * width) + "]"]
    for level in range(1, levels):
        items = ", ".join([f"*a{level - 1}"] * width)
        lines.append(f"a{level}: &a{level} [{items}]")
    lines.append(f"image: map.pgm\nresolution: 0.05\norigin: *a{levels - 1}")
    lines.append("occupied_thresh: 0.65\nfree_thresh: 0.196")
    return "\n".join(lines) + "\n"


@settings(max_examples=10, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(levels=st.integers(6, 14), width=st.integers(6, 12))
def test_alias_bombs_are_refused_while_parsing(
    work: Path, room_map: Path, levels: int, width: int
) -> None:
    bomb = work / "bomb.yaml"
    bomb.write_text(_alias_bomb(levels, width))
    result = run_hostile(work, "import-map", str(bomb))
    assert result.code == 2
    assert result.codes() == ["M002"]
    assert len(result.err) < 1000  # the expanded value is never echoed


def test_a_small_aliased_map_still_reads(work: Path, room_map: Path) -> None:
    # aliases are not refused as such: only what they expand to counts
    text = room_map.read_text().replace(
        "origin: [0.0, 0.0, 0.0]", "o: &o [0.0, 0.0, 0.0]\norigin: *o"
    )
    (work / "aliased.yaml").write_text(text)
    result = run_hostile(
        work,
        "import-map",
        "aliased.yaml",
        "--region",
        "a",
        "0.3",
        "0.3",
        "0.8",
        "0.8",
        "--task",
        "visit a",
    )
    assert result.code == 0, result.err


@pytest.mark.parametrize(("width", "height"), [(60000, 60000), (2**31 - 1, 3), (9000, 9000)])
def test_an_image_header_declaring_too_many_cells_is_refused(
    work: Path, width: int, height: int
) -> None:
    (work / "map.pgm").write_bytes(f"P5\n{width} {height}\n255\n".encode())
    (work / "map.yaml").write_text(MAP_YAML.format(image="map.pgm"))
    result = run_hostile(work, "import-map", "map.yaml")
    assert result.code == 2
    assert result.codes() == ["M006"]


@pytest.mark.parametrize(
    ("flag", "value", "code"),
    [
        ("--radius", "nan", "M012"),
        ("--radius", "inf", "M012"),
        ("--radius", "-0.1", "M012"),
        ("--min-area", "nan", "M012"),
        ("--tolerance", "inf", "M012"),
        ("--max-speed", "nan", "M018"),
        ("--max-speed", "0", "M018"),
        ("--max-speed", "-inf", "M018"),
    ],
)
def test_non_finite_import_settings_are_refused(
    work: Path, room_map: Path, flag: str, value: str, code: str
) -> None:
    result = run_hostile(
        work,
        "import-map",
        str(room_map),
        "--region",
        "a",
        "0.3",
        "0.3",
        "0.8",
        "0.8",
        "--task",
        "visit a",
        f"{flag}={value}",
        located=code != "M018",
    )
    assert result.code == 2
    assert result.codes() == [code]


@pytest.mark.parametrize("resolution", ["1.0e-300", "1.0e+300", "0.0", "-0.05", ".nan", ".inf"])
def test_extreme_resolutions_are_refused(work: Path, room_map: Path, resolution: str) -> None:
    room_map.write_text(room_map.read_text().replace("0.05", resolution))
    result = run_hostile(work, "import-map", str(room_map))
    assert result.code == 2
    assert result.codes() == ["M004"]


def test_a_mask_with_another_origin_is_refused(work: Path, room_map: Path) -> None:
    mask = write_map(work, np.ones((40, 40), dtype=bool), "mask")
    mask.write_text(mask.read_text().replace("[0.0, 0.0, 0.0]", "[1.0, 0.0, 0.0]"))
    result = run_hostile(work, "import-map", str(room_map), "--keepout", str(mask))
    assert result.code == 2
    assert result.codes() == ["M013"]


@settings(
    max_examples=15,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(
    x=st.one_of(st.floats(-1.0, 3.0), st.sampled_from([float("nan"), float("inf")])),
    y=st.floats(-1.0, 3.0),
)
def test_import_map_writes_only_missions_check_accepts(
    work: Path, room_map: Path, x: float, y: float
) -> None:
    out = work / "mission.yaml"
    out.unlink(missing_ok=True)
    result = run_hostile(
        work,
        "import-map",
        str(room_map),
        "--region",
        "a",
        "0.3",
        "0.3",
        "0.8",
        "0.8",
        "--task",
        "visit a",
        "--start",
        _number(x),
        _number(y),
        "-o",
        str(out),
        may_write=["mission.yaml"],
    )
    if result.code == 0:
        checked = run_hostile(work, "check", str(out))
        assert checked.code == 0, checked.err  # never a mission check refuses
        assert yaml.safe_load(out.read_text())["robot"]["start"] == [x, y]
    else:
        assert result.code == 2
        assert result.codes() == ["M018"]
        assert not out.exists()


def _number(value: float) -> str:
    """``value`` exactly, in a form argparse never takes for an option (``-1e-12`` it does)."""
    return repr(value) if not math.isfinite(value) else f"{Decimal(value):f}"


def test_nan_min_area_no_longer_drops_the_obstacle(work: Path, room_map: Path) -> None:
    # the wall stub is an obstacle of the main piece: with a NaN minimum area it was dropped
    kept = maps.import_map(room_map)
    assert kept.holes or len(kept.boundary) > 4
    result = run_hostile(work, "import-map", str(room_map), "--min-area", "nan")
    assert result.code == 2


def test_a_checkerboard_map_is_answered(work: Path) -> None:
    cells = np.indices((400, 400)).sum(axis=0) % 2 == 1
    write_map(work, cells, "checker")
    (work / "mission.yaml").write_text(MISSION.format(map="checker.yaml"))
    result = run_hostile(work, "check", "mission.yaml")
    # 80,000 one-cell pieces, each below the minimum area: an answer, not a stall
    assert result.code == 1
    assert result.codes()


def test_a_dithered_map_of_many_pieces_is_m019(work: Path) -> None:
    rows, cols = np.indices((200, 200))
    write_map(work, (rows % 3 < 2) & (cols % 3 < 2), "dots")  # 4,356 pieces of 4 cells
    (work / "mission.yaml").write_text(MISSION.format(map="dots.yaml"))
    result = run_hostile(work, "check", "mission.yaml")
    assert result.code == 1
    assert result.codes() == ["M019"]
    assert result.err.startswith("mission.yaml:4:")
