"""Readings given to a reactive mission's executor: by hand (``ReactiveExecutor.command``) and
from a sensor file (``tlmpc simulate --sensors FILE``).

* readings that leave out a sensor, or name one the mission does not have, are a usage error
  with its code (Q125), not a KeyError or a silently dropped name;
* a file reading that breaks an assumption is refused at the row that gives it (Q120), even
  when other sensors are read at the same instant on earlier rows.
"""

from __future__ import annotations

import io
from pathlib import Path

import pytest

import tlmpc
from tlmpc.base.errors import UsageError
from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def guard(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("guard") / "out"
    err = io.StringIO()
    code = main(
        ["compile", str(ROOT / "specs" / "reactive" / "guard.yaml"), "-o", str(out)],
        out=io.StringIO(),
        err=err,
    )
    assert code == 0, err.getvalue()
    return out


@pytest.mark.parametrize(
    ("readings", "said"),
    [
        ({"person": False}, "no reading of alarm"),
        ({"person": False, "alarm": False, "alram": True}, "no sensor called alram"),
    ],
)
def test_readings_that_do_not_fit_the_mission_are_refused(
    guard: Path, readings: dict[str, bool], said: str
) -> None:
    executor = tlmpc.reactive_executor(guard)
    executor.command((1.0, 1.0), 0.0, {"person": False, "alarm": False})
    with pytest.raises(UsageError) as caught:
        executor.command((1.05, 1.0), 0.05, readings)
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == "Q125"
    assert said in diagnostic.message
    assert diagnostic.hint is not None
    # by name, as mission.json keeps the sensors (the file declares person first)
    assert "alarm, person" in diagnostic.hint


@pytest.mark.parametrize("alarm_first", [False, True])
def test_the_refusal_points_at_the_breaking_row(
    guard: Path, tmp_path: Path, alarm_first: bool
) -> None:
    rows = ["0,person,false", "0,alarm,true"]  # guard.yaml assumes !alarm at the start
    if alarm_first:
        rows.reverse()
    sensors = tmp_path / "sensors.csv"
    sensors.write_text("t,sensor,value\n" + "\n".join(rows) + "\n")
    err = io.StringIO()
    code = main(
        ["simulate", str(guard), "--sensors", str(sensors), "--events", "5"],
        out=io.StringIO(),
        err=err,
    )
    assert code == 1
    breaking = 2 + rows.index("0,alarm,true")  # the header is line 1
    assert f"sensors.csv:{breaking}:1: error[Q120]" in err.getvalue()
