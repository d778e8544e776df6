"""End to end: every shipped mission compiles, its artifacts validate, its trace verifies."""

from __future__ import annotations

import io
import json
import subprocess
import sys
from pathlib import Path
from xml.etree import ElementTree

import pytest

from tlmpc.cli import main
from tlmpc.io.schema_check import validation_errors

ROOT = Path(__file__).resolve().parents[2]
SPECS = sorted((ROOT / "specs").glob("*.yaml"))
SCHEMA_OF = {
    "mission.json": "mission-artifact",
    "abstraction.json": "abstraction",
    "automaton.json": "automaton",
    "witness.json": "witness",
    "controllers.json": "controllers",
    "trace.json": "trace",
    "verdict.json": "verdict",
    "summary.json": "summary",
}


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Compile every spec once for the whole module (Example 8 included)."""
    base = tmp_path_factory.mktemp("compiled")
    outputs = {}
    for spec in SPECS:
        out = base / spec.stem
        code, _, err = run_cli("compile", str(spec), "-o", str(out), "-q")
        assert code == 0, f"{spec.name}: exit {code}\n{err}"
        outputs[spec.stem] = out
    return outputs


def test_specs_exist() -> None:
    names = {p.stem for p in SPECS}
    assert {"example1", "example6", "example7", "example8"} <= names


@pytest.mark.parametrize("spec", [p.stem for p in SPECS])
def test_every_artifact_validates_against_its_schema(compiled: dict[str, Path], spec: str) -> None:
    out = compiled[spec]
    for name, schema in SCHEMA_OF.items():
        document = json.loads((out / name).read_text())
        assert validation_errors(document, schema) == [], f"{spec}/{name}"
    assert (out / "automaton.hoa").read_text().startswith("HOA: v1")
    assert not (out / "plan.png").exists()  # drawn with --png only
    root = ElementTree.fromstring((out / "plan.svg").read_bytes())
    assert root.tag == "{http://www.w3.org/2000/svg}svg"


@pytest.mark.parametrize("spec", [p.stem for p in SPECS])
def test_every_compiled_trace_verifies(compiled: dict[str, Path], spec: str) -> None:
    code, out, err = run_cli("verify", str(compiled[spec] / "trace.json"), "--json")
    assert code == 0, err
    verdict = json.loads(out)["result"]
    assert verdict["satisfied"] is True


@pytest.mark.parametrize("spec", [p.stem for p in SPECS])
def test_trace_verifies_under_closed_convention_too(compiled: dict[str, Path], spec: str) -> None:
    # Strict margins keep compiled trajectories off region boundaries except at crossings,
    # so only formulas that forbid a handover could differ; none of the specs does.
    code, _, err = run_cli("verify", str(compiled[spec] / "trace.json"), "--boundary", "closed")
    assert code == 0, err


def test_plot_is_reproducible_byte_for_byte(compiled: dict[str, Path], tmp_path: Path) -> None:
    original = compiled["example1"]
    copy = tmp_path / "copy"
    copy.mkdir()
    for item in original.iterdir():
        (copy / item.name).write_bytes(item.read_bytes())
    code, _, err = run_cli("plot", str(copy))
    assert code == 0, err
    assert (copy / "plan.svg").read_bytes() == (original / "plan.svg").read_bytes()
    pngs = []
    for _ in range(2):
        code, _, err = run_cli("plot", str(copy), "--format", "png")
        assert code == 0, err
        pngs.append((copy / "plan.png").read_bytes())
    assert pngs[0][:8] == b"\x89PNG\r\n\x1a\n"
    assert pngs[0] == pngs[1]


def test_until_abstraction_stops_early(tmp_path: Path) -> None:
    out = tmp_path / "out"
    code, stdout, err = run_cli(
        "compile",
        str(ROOT / "specs" / "example1.yaml"),
        "-o",
        str(out),
        "--until",
        "abstraction",
        "--json",
    )
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == [
        ".tlmpc-output",
        "abstraction.json",
        "mission.json",
        "summary.json",
    ]
    summary = json.loads(stdout)["result"]
    assert [s["name"] for s in summary["stages"]] == ["load", "abstraction"]
    assert "[2/2] abstraction" in err


def test_progress_lines_and_quiet(tmp_path: Path) -> None:
    spec = str(ROOT / "specs" / "example1.yaml")
    code, _, err = run_cli("compile", spec, "-o", str(tmp_path / "a"), "--until", "automaton")
    assert code == 0
    assert [line.split()[1] for line in err.splitlines() if line.startswith("[")] == [
        "load",
        "abstraction",
        "automaton",
    ]
    code, _, err = run_cli("compile", spec, "-o", str(tmp_path / "b"), "--until", "automaton", "-q")
    assert code == 0
    assert err == ""


NO_PLAN = """\
version: 1
name: walled-off
workspace:
  boundary: {rect: [0, 0, 10, 4]}
  holes:
    - {rect: [4, -1, 5, 5]}
regions:
  home: {rect: [0.5, 0.5, 2, 2]}
  goal: {rect: [8, 1, 9, 2]}
robot: {start: [1, 1], max_speed: 1.0}
task:
  - visit goal
"""


def test_no_plan_exits_1_with_explanation_and_writes_nothing(tmp_path: Path) -> None:
    mission = tmp_path / "walled.yaml"
    # The hole cuts the boundary in two: clip it so the mission itself is valid.
    mission.write_text(NO_PLAN.replace("[4, -1, 5, 5]", "[4, 0, 5, 4]"))
    out = tmp_path / "out"
    code, _, err = run_cli("compile", str(mission), "-o", str(out))
    assert code == 1, err
    assert "goal" in err
    assert "error[P" in err
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["walled.yaml"]


def test_failed_run_keeps_previous_output(tmp_path: Path) -> None:
    out = tmp_path / "out"
    spec = str(ROOT / "specs" / "example1.yaml")
    assert run_cli("compile", spec, "-o", str(out), "--until", "abstraction", "-q")[0] == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    broken = tmp_path / "broken.yaml"
    broken.write_text("version: 1\nregoins: {}\n")
    code, _, err = run_cli("compile", str(broken), "-o", str(out))
    assert code == 1
    assert "broken.yaml:2:1" in err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_python_dash_m_entry_point(tmp_path: Path) -> None:
    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "tlmpc",
            "compile",
            str(ROOT / "specs" / "example1.yaml"),
            "-o",
            str(tmp_path / "out"),
            "--until",
            "automaton",
            "-q",
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert completed.returncode == 0, completed.stderr
    assert (tmp_path / "out" / "automaton.hoa").exists()


def test_a_compile_never_imports_cvxpy(tmp_path: Path) -> None:
    """cvxpy is a test oracle only: importing it would add about 0.5 s to every compile."""
    script = (
        "import sys, io\n"
        "from tlmpc.cli import main\n"
        f"argv = ['compile', {str(ROOT / 'specs' / 'example1.yaml')!r}, '-o', "
        f"{str(tmp_path / 'out')!r}, '-q']\n"
        "code = main(argv, io.StringIO(), io.StringIO())\n"
        "print(code, sorted(m for m in sys.modules if m.split('.')[0] == 'cvxpy'))\n"
    )
    completed = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert completed.stdout.strip() == "0 []"
