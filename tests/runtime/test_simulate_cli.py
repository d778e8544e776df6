"""``tlmpc simulate``: exit codes, the trace it writes (re-verified by ``tlmpc verify``), and
its usage errors."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pytest
import yaml

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def _compile(tmp_path: Path, name: str, **robot: Any) -> Path:
    document = yaml.safe_load((ROOT / "specs" / f"{name}.yaml").read_text())
    document["robot"].update(robot)
    mission = tmp_path / f"{name}.yaml"
    mission.write_text(yaml.safe_dump(document))
    out = tmp_path / f"{name}-out"
    code, _, err = run("compile", str(mission), "-o", str(out))
    assert code == 0, err
    return out


@pytest.fixture(scope="module")
def patrol(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _compile(tmp_path_factory.mktemp("patrol"), "patrol", disturbance=0.1)


@pytest.mark.parametrize("model", ["random", "adversarial"])
def test_a_run_within_the_bound_exits_0_and_its_trace_verifies(
    patrol: Path, tmp_path: Path, model: str
) -> None:
    trace = tmp_path / "trace.json"
    code, out, err = run(
        "simulate", str(patrol), "--model-disturbance", model, "--seed", "3", "-o", str(trace)
    )
    assert code == 0, out + err
    assert ": satisfied:" in out
    assert "re-plan" in out
    document = json.loads(trace.read_text())
    assert document["end"] == "loop"
    assert document["max_speed"] == pytest.approx(1.1)  # u plus w bounds the samples' speed
    code, out, _ = run("verify", str(trace))
    assert code == 0, out


def test_json_report(patrol: Path) -> None:
    code, out, _ = run("simulate", str(patrol), "--cycles", "1", "--json")
    assert code == 0
    envelope = json.loads(out)
    assert envelope["command"] == "simulate"
    assert envelope["exit_code"] == 0
    report = envelope["result"]
    assert report["outcome"] == "satisfied"
    assert report["laps"] == 1
    assert report["disturbance"] == {
        "bound": 0.1,
        "declared": 0.1,
        "model": "random",
        "seed": 0,
    }
    assert report["recoveries"] == []


def test_a_run_cut_before_a_lap_is_inconclusive_exit_4(patrol: Path) -> None:
    code, out, _ = run("simulate", str(patrol), "--duration", "1")
    assert code == 4, out
    assert "trace ends: open" in out


def test_pushing_above_the_declared_bound_says_so(patrol: Path) -> None:
    code, _, err = run("simulate", str(patrol), "--disturbance", "0.3", "--cycles", "1")
    assert "guarantee the task for |w| <= 0.1" in err
    assert code in (0, 1, 4)


@pytest.mark.parametrize(
    ("flags", "code"),
    [
        (("--disturbance", "-1"), "U080"),
        (("--disturbance", "nan"), "U080"),
        (("--cycles", "0"), "U081"),
        (("--cycles", "1.5"), "U081"),
        (("--duration", "inf"), "U081"),
        (("--dt", "0"), "U082"),
    ],
)
def test_bad_flags_exit_2_with_their_code(patrol: Path, flags: tuple[str, ...], code: str) -> None:
    status, _, err = run("simulate", str(patrol), *flags)
    assert status == 2
    assert f"error[{code}]" in err


def test_an_output_without_controllers_is_R020(tmp_path: Path) -> None:
    out = tmp_path / "partial"
    code, _, err = run("compile", str(ROOT / "specs" / "example1.yaml"), "-o", str(out))
    assert code == 0, err
    (out / "controllers.json").unlink()
    status, _, err = run("simulate", str(out))
    assert status == 2
    assert "error[R020]" in err


def test_an_unwritable_trace_path_is_U083(patrol: Path, tmp_path: Path) -> None:
    status, _, err = run("simulate", str(patrol), "--cycles", "1", "-o", str(tmp_path))
    assert status == 2
    assert "error[U083]" in err


def test_a_unicycle_simulation_exits_0(tmp_path: Path) -> None:
    out = _compile(tmp_path, "example1", model="unicycle", offset=0.2)
    code, out_text, err = run("simulate", str(out), "--heading", "1.5", "--cycles", "1")
    assert code == 0, out_text + err
    assert ": satisfied:" in out_text


def test_the_simulated_trace_describes_the_mission_as_the_compiled_one_does(
    tmp_path: Path,
) -> None:
    """Everything a trace takes from the mission (workspace pieces, the body's radius, the
    convention...) is the compiled trace's, so the verifier judges both on the same terms."""
    out = _compile(tmp_path, "patrol", radius=0.05)
    trace = tmp_path / "simulated.json"
    code, _, err = run("simulate", str(out), "--cycles", "1", "-o", str(trace))
    assert code == 0, err
    simulated = json.loads(trace.read_text())
    compiled = json.loads((out / "trace.json").read_text())
    assert simulated["radius"] == 0.05
    for key in ("ltl", "regions", "workspace", "boundary", "radius"):
        assert simulated[key] == compiled[key], key


def test_an_output_whose_mission_has_no_source_simulates(patrol: Path, tmp_path: Path) -> None:
    """``source`` (the mission file, named in diagnostics) is optional in the mission
    artifact's schema: simulate and stage read such a folder (they raised KeyError, exit 3)."""
    import shutil

    out = tmp_path / "no-source"
    shutil.copytree(patrol, out)
    mission = json.loads((out / "mission.json").read_text())
    del mission["source"]
    (out / "mission.json").write_text(json.dumps(mission))
    code, text, err = run("simulate", str(out), "--cycles", "1")
    assert code == 0, text + err
    assert ": satisfied:" in text
    code, text, err = run("stage", "control", str(out))
    assert code == 0, text + err
