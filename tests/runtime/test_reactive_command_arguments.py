"""`ReactiveExecutor.command` refuses a malformed position or readings with Q125, never a
bare TypeError or ValueError, and never reads a reading that is not true or false by its
truth (``"no"`` would be true)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import tlmpc
from tlmpc.io.outdir import write_artifacts
from tlmpc.pipeline.stages import compile_mission

ROOT = Path(__file__).resolve().parents[2]
QUIET = {"person": False, "alarm": False}


@pytest.fixture(scope="module")
def guard(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("guard")
    write_artifacts(folder, compile_mission(ROOT / "specs" / "reactive" / "guard.yaml").artifacts)
    return folder


def _refusal(guard: Path, point: Any, sensors: Any) -> str:
    executor = tlmpc.reactive_executor(guard)
    with pytest.raises(tlmpc.UsageError) as refused:
        executor.command(point, 0.0, sensors)
    return refused.value.diagnostics[0].code


@pytest.mark.parametrize("point", [None, "xy", "12", 5, (1.0,), (1.0, 1.0, 0.0), (np.nan, 1.0)])
def test_a_malformed_position_is_q125(guard: Path, point: Any) -> None:
    assert _refusal(guard, point, QUIET) == "Q125"


@pytest.mark.parametrize(
    "sensors",
    [
        None,
        3,
        ["person", "alarm"],
        {"person": "no", "alarm": False},
        {"person": None, "alarm": False},
        {"person": 2, "alarm": False},
        {"person": 0.5, "alarm": False},
    ],
)
def test_readings_that_are_not_true_or_false_are_q125(guard: Path, sensors: Any) -> None:
    assert _refusal(guard, (1.0, 1.0), sensors) == "Q125"


@pytest.mark.parametrize(
    "sensors",
    [
        {"person": True, "alarm": False},
        {"person": 1, "alarm": 0},
        {"person": np.bool_(True), "alarm": np.bool_(False)},
    ],
)
def test_truth_values_are_read(guard: Path, sensors: dict[str, Any]) -> None:
    executor = tlmpc.reactive_executor(guard)
    vx, vy = executor.command((1.0, 1.0), 0.0, sensors)
    assert np.isfinite([vx, vy]).all()
    assert executor.events[0].sensors == {"person": True, "alarm": False}
