"""``tlmpc simulate``: a run expected past the sample budget (R024) is refused at what sets its
length (``--dt`` when given, else the output folder whose plan sets the default dt), and the
``--dt`` and ``--duration`` its hint gives are accepted (checked by running them)."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest

from tlmpc.cli import main
from tlmpc.runtime import closed_loop

ROOT = Path(__file__).resolve().parents[2]

#: A budget small enough that example 1's default run passes it.
BUDGET = 200


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("budget") / "out"
    code, _, err = run("compile", str(ROOT / "specs" / "example1.yaml"), "-o", str(out), "-q")
    assert code == 0, err
    return out


def _hinted(err: str, flag: str) -> str:
    found = re.search(rf"{flag} ([0-9.e+-]+)", err.split("hint:")[1])
    assert found is not None, err
    return found.group(1)


def test_the_default_dt_is_refused_at_the_folder_with_a_hint_that_fits(
    compiled: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(closed_loop, "MAX_SAMPLES", BUDGET)
    code, _, err = run("simulate", str(compiled))
    assert code == 2, err
    assert err.startswith(f"{compiled}: error[R024]:"), err
    assert "the default dt" in err
    assert "leave it out" not in err
    for flag in ("--dt", "--duration"):
        value = _hinted(err, flag)
        code, _, again = run("simulate", str(compiled), flag, value)
        assert code != 2, (flag, value, again)  # the hint's value runs (within the budget)


def test_a_given_dt_is_refused_at_the_flag(compiled: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(closed_loop, "MAX_SAMPLES", BUDGET)
    code, _, err = run("simulate", str(compiled), "--dt", "0.0001")
    assert code == 2, err
    assert err.startswith("--dt 0.0001: error[R024]:"), err
    value = _hinted(err, "--dt")
    assert float(value) > 0.0001
    code, _, again = run("simulate", str(compiled), "--dt", value)
    assert code != 2, again


@pytest.mark.parametrize(("spec", "timed"), [("deadline.yaml", True), ("example1.yaml", False)])
def test_a_task_with_time_bounds_has_a_quarter_of_the_budget(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, spec: str, timed: bool
) -> None:
    # the verifier searches each bound's windows over the whole trace: four times a sample's
    # cost, so a quarter of the samples
    out = tmp_path / "out"
    code, _, err = run("compile", str(ROOT / "specs" / spec), "-o", str(out), "-q")
    assert code == 0, err
    monkeypatch.setattr(closed_loop, "MAX_SAMPLES", 4 * BUDGET)
    monkeypatch.setattr(closed_loop, "MAX_TIMED_SAMPLES", BUDGET)
    dt = 0.5  # a run of 2.5 budgets of samples: past the timed budget, within the other
    code, _, err = run("simulate", str(out), "--dt", str(dt), "--duration", str(2.5 * BUDGET * dt))
    if timed:
        assert code == 2, err
        assert f"more than the budget of {BUDGET:,} (a task with time bounds)" in err, err
    else:
        assert "R024" not in err, err
