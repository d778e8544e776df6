"""`tlmpc export`: the models it writes, its errors, and reading SPIN's trails back."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
from spin_runner import parse_trail

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def example1(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("export") / "example1"
    spec = str(ROOT / "specs" / "example1.yaml")
    code, _, err = run_cli("compile", spec, "-o", str(out), "--until", "abstraction", "-q")
    assert code == 0, err
    return out


def test_promela_keeps_the_no_bounce_rule_unless_asked(example1: Path) -> None:
    code, model, _ = run_cli("export", str(example1), "--format", "promela")
    assert code == 0
    assert "int prev = -1;" in model
    assert "nb[3*t + 0] != prev" in model
    assert "ltl task { !(" in model
    code, plain, _ = run_cli("export", str(example1), "--format", "promela", "--bounce")
    assert code == 0
    assert "prev" not in plain
    assert "ltl task { !(" in plain


def test_smv_to_a_file(example1: Path, tmp_path: Path) -> None:
    target = tmp_path / "model.smv"
    code, out, err = run_cli("export", str(example1), "--format", "smv", "-o", str(target))
    assert code == 0
    assert out == ""
    assert f"wrote {target}" in err
    model = target.read_text()
    assert model.startswith("-- tlmpc export of")
    assert "TRANS next(t) = t | next(t) != prev;" in model
    assert "LTLSPEC !(" in model


def test_dot_has_one_node_per_triangle(example1: Path) -> None:
    code, dot, _ = run_cli("export", str(example1), "--format", "dot")
    assert code == 0
    assert dot.startswith("graph ")
    triangles = json.loads((example1 / "abstraction.json").read_text())["triangles"]
    assert dot.count("label=") == len(triangles)  # one node per triangle of the mesh


def test_errors_exit_2_and_write_nothing(example1: Path, tmp_path: Path) -> None:
    code, _, err = run_cli("export", str(tmp_path))
    assert code == 2
    assert "error[U020]" in err
    target = tmp_path / "missing" / "model.pml"
    code, _, err = run_cli("export", str(example1), "-o", str(target))
    assert code == 2
    assert "error[U021]" in err
    assert not target.parent.exists()


def test_parse_trail_reads_moves_and_the_cycle_start() -> None:
    replay = """\
ltl task: ! (([] (<> ((t==1)))) && ([] (<> ((t==2)))))
Never claim moves to line 5	[(1)]
          tlmpc: t = 1
  <<<<<START OF CYCLE>>>>>
Never claim moves to line 4	[((t==1))]
          tlmpc: t = 2
          tlmpc: t = 0
          tlmpc: t = 1
spin: trail ends after 10 steps
		t = 1
"""
    assert parse_trail(replay) == ((1, 2, 0, 1), 1)
    assert parse_trail("          tlmpc: t = 7\nspin: trail ends after 3 steps\n") == ((7,), None)
