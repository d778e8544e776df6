"""Fixtures of the hostile-input tests: a compiled output to edit, a map to attack."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]

MAP_YAML = (
    "image: {image}\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
    "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n"
)


@pytest.fixture(scope="session")
def compiled_once(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``tlmpc compile specs/patrol.yaml`` once per session (never edited: copy it)."""
    out = tmp_path_factory.mktemp("compiled") / "out"
    assert main(["compile", str(ROOT / "specs" / "patrol.yaml"), "-o", str(out), "-q"]) == 0
    return out


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A folder holding every input of the test, and the working directory of its runs (so a
    relative write could only land inside it)."""
    root = tmp_path / "work"
    root.mkdir()
    monkeypatch.chdir(root)
    return root


@pytest.fixture
def compiled(work: Path, compiled_once: Path) -> Path:
    """A copy of the compiled output inside ``work``, free to edit."""
    out = work / "out"
    shutil.copytree(compiled_once, out)
    return out


def write_map(folder: Path, cells: np.ndarray, name: str = "map") -> Path:
    """A map_server map of ``cells`` (True free, False occupied) in ``folder``."""
    pixels = np.where(cells, 254, 0).astype(np.uint8)
    Image.fromarray(pixels).save(folder / f"{name}.pgm")
    path = folder / f"{name}.yaml"
    path.write_text(MAP_YAML.format(image=f"{name}.pgm"))
    return path


@pytest.fixture
def room_map(work: Path) -> Path:
    """A 40 x 40-cell room (2 m square) with a wall stub: free inside, occupied border."""
    cells = np.zeros((40, 40), dtype=bool)
    cells[2:-2, 2:-2] = True
    cells[18:22, 2:15] = False
    return write_map(work, cells)
