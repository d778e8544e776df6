"""A mission whose workspace is an occupancy map: what `compile` writes, every reader accepts.

The map's workspace carries a field no drawn workspace has (``map_tolerance``, how far the
simplified rings may lie from the cells), so its artifacts are the ones a schema written for
drawn workspaces alone would refuse.  The map is made here: a free square of cells with an
occupied block in its middle.
"""

from __future__ import annotations

import io
from pathlib import Path

import pytest
import yaml

from tlmpc.cli import main
from tlmpc.io.artifacts import ARTIFACT_SCHEMAS, read_artifacts

SIDE = 20  # cells
RESOLUTION = 0.5  # metres per cell


def _write_map(folder: Path) -> Path:
    rows = []
    for row in range(SIDE):
        blocked = 8 <= row < 12
        rows.append(bytes(0 if blocked and 8 <= col < 12 else 254 for col in range(SIDE)))
    (folder / "room.pgm").write_bytes(f"P5\n{SIDE} {SIDE}\n255\n".encode() + b"".join(rows))
    meta = {
        "image": "room.pgm",
        "resolution": RESOLUTION,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    path = folder / "room.yaml"
    path.write_text(yaml.safe_dump(meta))
    return path


def _run(*argv: str) -> tuple[int, str]:
    stdout, stderr = io.StringIO(), io.StringIO()
    return main(list(argv), out=stdout, err=stderr), stdout.getvalue() + stderr.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("map-mission")
    _write_map(folder)
    mission = {
        "version": 1,
        "workspace": {"map": "room.yaml"},
        "regions": {
            "dock": {"rect": [1.0, 1.0, 2.0, 2.0]},
            "shelf": {"rect": [8.0, 8.0, 9.0, 9.0]},
        },
        "robot": {"start": [8.0, 1.5], "radius": 0.2},
        "task": ["visit dock then shelf"],
    }
    path = folder / "mission.yaml"
    path.write_text(yaml.safe_dump(mission))
    out = folder / "out"
    code, text = _run("compile", str(path), "-o", str(out))
    assert code == 0, text
    return out


def test_the_trace_keeps_the_maps_tolerance(compiled: Path) -> None:
    trace = yaml.safe_load((compiled / "trace.json").read_text())
    assert trace["workspace"]["map_tolerance"] > 0.0  # the case this file is about


def test_every_artifact_matches_its_schema(compiled: Path) -> None:
    names = tuple(name for name in ARTIFACT_SCHEMAS if (compiled / name).is_file())
    assert {"mission.json", "trace.json", "verdict.json"} <= set(names)
    read_artifacts(compiled, names)


@pytest.mark.parametrize(
    "command",
    [
        ("plot", "{out}"),
        ("export-plan", "{out}", "--format", "geojson", "-o", "{tmp}/plan.geojson"),
        ("view", "{out}", "-o", "{tmp}/view.html"),
        ("verify", "{out}/trace.json"),
        ("export", "{out}", "--format", "promela", "-o", "{tmp}/plan.pml"),
    ],
)
def test_the_readers_accept_the_output(
    compiled: Path, tmp_path: Path, command: tuple[str, ...]
) -> None:
    argv = [part.format(out=compiled, tmp=tmp_path) for part in command]
    code, text = _run(*argv)
    assert code == 0, text
