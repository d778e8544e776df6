"""`tlmpc export-plan` on an output without a trajectory says what the output lacks and what
to run for it: a reactive mission's output holds a strategy (its path depends on the sensors,
so there is no one plan to export), and an output whose compile stopped early needs its
remaining stages, not another compile."""

from __future__ import annotations

import io
from pathlib import Path

from reactive_missions import GUARD_UNREALIZABLE

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]


def _run(*argv: str) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, err.getvalue()


def _hint(err: str) -> str:
    (line,) = [line for line in err.splitlines() if line.startswith("  hint: ")]
    return line


def test_a_reactive_output_is_a_strategy_not_a_plan(tmp_path: Path) -> None:
    out = tmp_path / "out"
    code, err = _run("compile", str(ROOT / "specs/reactive/guard.yaml"), "-o", str(out), "-q")
    assert code == 0, err
    code, err = _run("export-plan", str(out))
    assert code == 2
    assert "error[M080]" in err
    hint = _hint(err)
    assert "strategy, not a plan" in hint
    assert "tlmpc simulate" in hint
    assert "tlmpc compile" not in hint


def test_an_output_stopped_before_simulate_names_the_stage(tmp_path: Path) -> None:
    out = tmp_path / "out"
    mission = str(ROOT / "specs/reach-avoid.yaml")
    code, err = _run("compile", mission, "-o", str(out), "--until", "control", "-q")
    assert code == 0, err
    code, err = _run("export-plan", str(out))
    assert code == 2
    assert "tlmpc stage simulate" in _hint(err)
    # and that stage is what the export needed
    code, err = _run("stage", "simulate", str(out))
    assert code == 0, err
    code, err = _run("export-plan", str(out), "-o", str(tmp_path / "plan.yaml"))
    assert code == 0, err


def test_a_folder_without_an_output_asks_for_a_compile(tmp_path: Path) -> None:
    code, err = _run("export-plan", str(tmp_path))
    assert code == 2
    assert "run `tlmpc compile MISSION -o DIR` first" in _hint(err)


def test_an_unrealizable_output_points_to_its_counterstrategy(tmp_path: Path) -> None:
    source = tmp_path / "guard.yaml"
    source.write_text(GUARD_UNREALIZABLE)
    out = tmp_path / "out"
    code, err = _run("compile", str(source), "-o", str(out), "-q")
    assert code == 1, err
    code, err = _run("export-plan", str(out))
    assert code == 2
    hint = _hint(err)
    assert "counterstrategy.json" in hint
    assert "tlmpc simulate" not in hint, "an unrealizable mission has no strategy to run"
    # and the command the hint names draws it
    assert _run("plot", str(out))[0] == 0
