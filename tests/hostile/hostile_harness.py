"""The acceptance rules every hostile input is held to, and the fixtures of this folder's tests.

A run of ``tlmpc`` on a hostile input must

* exit 0, 1, 2 or 4 (never 3, never a traceback);
* report any refusal as a located diagnostic ``FILE[:LINE[:COL]]: error[CODE]: ...`` whose
  lines carry no raw control or direction character;
* write nothing but the paths it was asked to write, and change no other file.
"""

from __future__ import annotations

import hashlib
import io
import os
import re
import shutil
import stat
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pytest
from PIL import Image

from tlmpc.cli import main

#: A diagnostic line: a location that names a file (not ``<input>``), a severity and a code.
LOCATED = re.compile(r"^(?!<input>)[^\s:][^:]*(:\d+){0,2}: (error|warning|note)\[[A-Z]\d{3}\]: ")
ANY_DIAGNOSTIC = re.compile(r"^\S.*: (error|warning|note)\[[A-Z]\d{3}\]: ")

#: Characters no line of tlmpc's output may carry raw: C0 (but newline and tab), DEL, C1, the
#: direction controls and the Unicode line separators (listed from the Unicode standard).
FORBIDDEN = re.compile(
    "[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069\u2028\u2029]"
)


@dataclass(frozen=True)
class Run:
    """What one ``tlmpc`` run answered."""

    code: int
    out: str
    err: str

    def codes(self) -> list[str]:
        """The diagnostic codes on stderr, in order."""
        return re.findall(r": (?:error|warning|note)\[([A-Z]\d{3})\]: ", self.err)


def snapshot(root: Path) -> dict[str, tuple[int, str]]:
    """Every entry under ``root``: its mode and, for a regular file, the hash of its bytes."""
    entries: dict[str, tuple[int, str]] = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            path = Path(folder) / name
            info = os.lstat(path)
            digest = ""
            if stat.S_ISREG(info.st_mode):
                digest = hashlib.sha256(path.read_bytes()).hexdigest()
            entries[str(path.relative_to(root))] = (stat.S_IFMT(info.st_mode), digest)
    return entries


def run(*argv: str) -> Run:
    """``tlmpc ARGV`` in this process."""
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return Run(code, out.getvalue(), err.getvalue())


def run_hostile(root: Path, *argv: str, may_write: Iterable[str] = (), located: bool = True) -> Run:
    """Run ``tlmpc ARGV`` and check the acceptance rules; ``root`` is the folder holding every
    input, and ``may_write`` the entries (relative to it) the run may create or replace."""
    before = snapshot(root)
    result = run(*argv)
    after = snapshot(root)
    assert result.code in (0, 1, 2, 4), result.err
    assert "Traceback" not in result.err, result.err
    assert "internal error" not in result.err, result.err
    for line in result.err.splitlines():
        assert not FORBIDDEN.search(line), repr(line)
    allowed = set(may_write)
    changed = {
        name
        for name in before.keys() | after.keys()
        if before.get(name) != after.get(name)
        and not any(name == a or name.startswith(a + os.sep) for a in allowed)
    }
    assert not changed, f"files changed outside the run's outputs: {sorted(changed)}"
    if result.code == 2:
        diagnostics = [line for line in result.err.splitlines() if ANY_DIAGNOSTIC.match(line)]
        assert diagnostics, result.err
        if located:
            assert any(LOCATED.match(line) for line in diagnostics), result.err
    return result


# --- fixtures (imported by the test modules under their *_fixture names) ---------------

ROOT = Path(__file__).resolve().parents[2]

MAP_YAML = (
    "image: {image}\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
    "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n"
)


@pytest.fixture(scope="session", name="compiled_once")
def compiled_once_fixture(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``tlmpc compile specs/patrol.yaml`` once per session (never edited: copy it)."""
    out = tmp_path_factory.mktemp("compiled") / "out"
    assert main(["compile", str(ROOT / "specs" / "patrol.yaml"), "-o", str(out), "-q"]) == 0
    return out


@pytest.fixture(name="work")
def work_fixture(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A folder holding every input of the test, and the working directory of its runs (so a
    relative write could only land inside it)."""
    root = tmp_path / "work"
    root.mkdir()
    monkeypatch.chdir(root)
    return root


@pytest.fixture(name="compiled")
def compiled_fixture(work: Path, compiled_once: Path) -> Path:
    """A copy of the compiled output inside ``work``, free to edit."""
    out = work / "out"
    shutil.copytree(compiled_once, out)
    return out


def write_map(folder: Path, cells: npt.NDArray[np.bool_], name: str = "map") -> Path:
    """A map_server map of ``cells`` (True free, False occupied) in ``folder``."""
    pixels = np.where(cells, 254, 0).astype(np.uint8)
    Image.fromarray(pixels).save(folder / f"{name}.pgm")
    path = folder / f"{name}.yaml"
    path.write_text(MAP_YAML.format(image=f"{name}.pgm"))
    return path


@pytest.fixture(name="room_map")
def room_map_fixture(work: Path) -> Path:
    """A 40 x 40-cell room (2 m square) with a wall stub: free inside, occupied border."""
    cells = np.zeros((40, 40), dtype=bool)
    cells[2:-2, 2:-2] = True
    cells[18:22, 2:15] = False
    return write_map(work, cells)
