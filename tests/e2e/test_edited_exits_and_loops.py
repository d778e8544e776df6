"""Edited controllers.json whose steps lead elsewhere than the plan: U042 at the file, exit 2.

Two edits passed the checks and failed inside the simulator with exit 3 ("please report this
mission"): a `loop_start` on a plan that ends in a stay (the simulator ran a "cycle" from the
stay's limit point), and a cell step with a kept side marked as an exit (the re-check then no
longer asked the field to push inward there, and the robot left its cell across it).
"""

from __future__ import annotations

import io
import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE1 = (ROOT / "specs" / "example1.yaml").read_text()
KEPT, EXIT = -1, -2


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def _compile(directory: Path, text: str) -> Path:
    mission = directory / "mission.yaml"
    mission.write_text(text)
    out = directory / "out"
    code, _, err = run_cli("compile", str(mission), "-o", str(out), "-q")
    assert code == 0, err
    return out


@pytest.fixture(scope="module")
def staying(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _compile(tmp_path_factory.mktemp("staying"), EXAMPLE1)


@pytest.fixture(scope="module")
def on_cells(tmp_path_factory: pytest.TempPathFactory) -> Path:
    # half max_speed pushes: Example 1 is planned on convex cells
    text = EXAMPLE1.replace("max_speed: 1.0}", "max_speed: 1.0, disturbance: 0.5}")
    assert text != EXAMPLE1
    return _compile(tmp_path_factory.mktemp("cells"), text)


def _copy(source: Path, tmp_path: Path) -> Path:
    copy = tmp_path / "copy"
    shutil.copytree(source, copy)
    return copy


@pytest.mark.parametrize("first", [0, 1, -1])
def test_a_loop_start_on_a_plan_that_ends_staying_is_refused(
    staying: Path, tmp_path: Path, first: int
) -> None:
    copy = _copy(staying, tmp_path)
    path = copy / "controllers.json"
    document = json.loads(path.read_text())
    assert document["loop_start"] is None
    assert document["steps"][-1]["stay"]
    document["loop_start"] = first % len(document["steps"])
    path.write_text(json.dumps(document))
    code, _, err = run_cli("stage", "simulate", str(copy))
    assert code == 2, err
    assert err.startswith(f"{path}: error[U042]: controllers.json"), err
    assert "stay" in err


def _neighbour(abstraction: dict[str, Any], triangle: int, facet: int) -> int:
    """The triangle across ``facet`` (opposite corner ``facet``), from the mesh's corners: the
    one other triangle holding both ends of that side (-1: none)."""
    corners = abstraction["triangles"][triangle]
    side = {corners[(facet + 1) % 3], corners[(facet + 2) % 3]}
    others = [
        t for t, tri in enumerate(abstraction["triangles"]) if t != triangle and side <= set(tri)
    ]
    return others[0] if others else -1


def test_a_kept_side_marked_as_an_exit_is_refused(on_cells: Path, tmp_path: Path) -> None:
    copy = _copy(on_cells, tmp_path)
    path = copy / "controllers.json"
    abstraction = json.loads((copy / "abstraction.json").read_text())
    document = json.loads(path.read_text())
    steps = document["steps"]
    # a cell move with a kept side; the next step's cell, read from the document
    moves = [
        (k, step["cell"])
        for k, step in enumerate(steps[:-1])
        if "cell" in step and step["cell"]["direction"] is not None
    ]
    k, cell = next((k, cell) for k, cell in moves if any(KEPT in row for row in cell["across"]))
    kept = [(p, f) for p, row in enumerate(cell["across"]) for f, a in enumerate(row) if a == KEPT]
    following = steps[k + 1]
    entered = (
        set(following["cell"]["triangles"]) if "cell" in following else {following["triangle"]}
    )
    piece, facet = kept[0]
    # the oracle: across that side lies a wall or a triangle outside the next step's cell
    assert _neighbour(abstraction, cell["triangles"][piece], facet) not in entered
    cell["across"][piece][facet] = EXIT
    # a constant field along the side's outward normal would now pass the rows that remain;
    # the edit alone is enough to be refused
    path.write_text(json.dumps(document))
    code, _, err = run_cli("stage", "simulate", str(copy))
    assert code == 2, err
    assert err.startswith(f"{path}: error[U042]: controllers.json"), err
    assert "into the next step's cell" in err


def test_an_interface_side_marked_as_kept_is_refused(on_cells: Path, tmp_path: Path) -> None:
    copy = _copy(on_cells, tmp_path)
    path = copy / "controllers.json"
    document = json.loads(path.read_text())
    step = next(s for s in document["steps"] if s.get("cell") and s["cell"]["direction"])
    row = next(r for r in step["cell"]["across"] if EXIT in r)
    row[row.index(EXIT)] = KEPT
    path.write_text(json.dumps(document))
    code, _, err = run_cli("stage", "simulate", str(copy))
    assert code == 2, err
    assert "U042" in err


def test_untouched_cell_controllers_still_simulate(on_cells: Path, tmp_path: Path) -> None:
    copy = _copy(on_cells, tmp_path)
    code, _, err = run_cli("stage", "simulate", str(copy))
    assert code == 0, err
    assert (copy / "trace.json").read_bytes() == (on_cells / "trace.json").read_bytes()
    assert np.isfinite(json.loads((copy / "trace.json").read_text())["points"][-1]).all()
