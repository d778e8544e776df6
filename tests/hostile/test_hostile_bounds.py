"""Bounded work and clean ends: sample budgets, ROS stamps, bag sizes, signals, extreme
numbers, wrong-typed API calls."""

from __future__ import annotations

import json
import signal
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hostile_harness import (  # noqa: F401 (fixtures, found by their names)
    compiled_fixture,
    compiled_once_fixture,
    run_hostile,
    work_fixture,
)
from hypothesis import given
from hypothesis import strategies as st
from robot_data import write_bag

import tlmpc
import tlmpc.cli
from tlmpc.importers import logs
from tlmpc.runtime import closed_loop

ROOT = Path(__file__).resolve().parents[2]
PATROL = str(ROOT / "specs" / "patrol.yaml")


@pytest.mark.parametrize("dt", ["1e-9", "1e-300", "5e-324"])
def test_a_tiny_dt_is_refused_before_running(compiled: Path, work: Path, dt: str) -> None:
    result = run_hostile(work, "simulate", "out", "--dt", dt, located=False)
    assert result.code == 2
    assert result.codes() == ["R024"]


def test_a_run_past_the_sample_budget_ends_inconclusive(
    compiled: Path, work: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # expected to fit (a nominal lap of ten samples) but running longer: the budget ends it
    monkeypatch.setattr(closed_loop, "MAX_SAMPLES", 50)
    monkeypatch.setattr(closed_loop, "TIME_CAP_FACTOR", 1e6)
    monkeypatch.setattr(closed_loop, "_nominal", lambda plan, cycles: 0.4)
    result = run_hostile(work, "simulate", "out", "--dt", "0.04", "--json")
    assert result.code == 4, result.err  # inconclusive: an answer, not an endless run
    report = json.loads(result.out)["result"]
    assert report["samples"] == 50
    assert report["ending"] == "open"
    # and a run expected past the budget is refused before it starts
    refused = run_hostile(work, "simulate", "out", "--dt", "0.004", located=False)
    assert refused.code == 2
    assert refused.codes() == ["R024"]


@pytest.mark.parametrize("seed", ["-1", "-99999999999999999999", str(2**128)])
def test_out_of_range_seeds_are_refused(compiled: Path, work: Path, seed: str) -> None:
    result = run_hostile(work, "simulate", "out", f"--seed={seed}", located=False)
    assert result.code == 2
    assert result.codes() == ["U084"]


@pytest.mark.parametrize("offset", [2.0**32, 1e12, 1e300])
def test_plan_times_beyond_a_ros_stamp_are_refused(
    compiled: Path, work: Path, offset: float
) -> None:
    path = compiled / "trace.json"
    trace = json.loads(path.read_text())
    trace["points"] = [[t + offset, x, y] for t, x, y in trace["points"]]
    path.write_text(json.dumps(trace))
    result = run_hostile(
        work, "export-plan", "out", "--format", "path-mcap", "-o", "p.mcap", located=False
    )
    assert result.code == 2
    assert result.codes() in (["M085"], ["V024"], ["U041"])
    assert not (work / "p.mcap").exists()


def _bag(work: Path, rows: list[tuple[int, float, float]], kind: str = "mcap") -> Path:
    suffix = {"mcap": "log.mcap", "ros1": "log.bag"}[kind]
    return write_bag(work / suffix, kind, {"/odom": ("nav_msgs/msg/Odometry", rows)})


@pytest.mark.parametrize("kind", ["mcap", "ros1"])
def test_a_bag_over_the_sample_limit_is_refused(
    work: Path, monkeypatch: pytest.MonkeyPatch, kind: str
) -> None:
    rows = [(1_000_000_000 + k * 10_000_000, 2.0 + 0.001 * k, 5.0) for k in range(30)]
    bag = _bag(work, rows, kind)
    monkeypatch.setattr(logs, "MAX_LOG_SAMPLES", 20)
    result = run_hostile(work, "verify", str(bag), "--mission", PATROL)
    assert result.code == 2
    assert result.codes() == ["M066"]


def test_a_bag_of_one_stamp_is_refused_like_the_csv(work: Path) -> None:
    rows = [(1_000_000_000, 2.0, 5.0), (1_000_000_000, 2.5, 5.0), (1_000_000_000, 3.0, 5.0)]
    bag = _bag(work, rows)
    csv = work / "log.csv"
    csv.write_text("t,x,y\n" + "".join(f"{t / 1e9},{x},{y}\n" for t, x, y in rows))
    answers = [
        run_hostile(work, "verify", str(log), "--mission", PATROL, located=False)
        for log in (bag, csv)
    ]
    assert [a.code for a in answers] == [2, 2]
    assert answers[0].codes() == answers[1].codes()
    assert set(answers[0].codes()) == {"V020"}


def test_sigterm_while_a_bag_is_read_is_143_not_a_corrupt_bag(
    work: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rosbags.highlevel import AnyReader

    rows = [(1_000_000_000 + k * 10_000_000, 2.0, 5.0 + 0.01 * k) for k in range(10)]
    bag = _bag(work, rows)
    original = AnyReader.deserialize

    def terminated(self: Any, raw: Any, kind: str) -> Any:
        signal.raise_signal(signal.SIGTERM)  # arrives in the middle of the reader's loop
        return original(self, raw, kind)

    monkeypatch.setattr(AnyReader, "deserialize", terminated)
    result = tlmpc.cli.main(["verify", str(bag), "--mission", PATROL])
    assert result == 143


def test_huge_coordinates_are_diagnosed_without_warnings(work: Path) -> None:
    log = work / "log.csv"
    log.write_text("t,x,y\n0,2,5\n1,1e308,5\n2,-1e308,1e308\n3,3,3\n")
    for command in (
        ("verify", "log.csv", "--mission", PATROL),
        ("view", "--log", "log.csv", "--mission", PATROL, "-o", "page.html"),
    ):
        result = run_hostile(work, *command, may_write=["page.html"])
        assert result.code == 2
        assert set(result.codes()) == {"V024"}
        assert "Warning" not in result.err


wrong_values = st.one_of(
    st.integers(),
    st.floats(allow_nan=True),
    st.binary(max_size=8),
    st.lists(st.integers(), max_size=3),
    st.none(),
    st.booleans(),
)


@given(value=wrong_values)
def test_wrong_typed_api_arguments_are_usage_errors(value: Any) -> None:
    calls: list[Callable[[], object]] = [
        lambda: tlmpc.compile(value),
        lambda: tlmpc.check(value),
        lambda: tlmpc.translate(value),
        lambda: tlmpc.read_output(value),
        lambda: tlmpc.verify_trace(value),
        lambda: tlmpc.executor(value),
    ]
    for call in calls:
        with pytest.raises(tlmpc.UsageError) as caught:
            call()
        assert caught.value.diagnostics[0].code == "U075"
        assert caught.value.exit_code == 2


@pytest.mark.parametrize(("number", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_signal_disguised_by_c_code_still_ends_the_run(
    monkeypatch: pytest.MonkeyPatch, number: signal.Signals, code: int
) -> None:
    # numpy's C import turns an exception raised by a signal handler into an ImportError
    def disguised(*args: object) -> int:
        try:
            signal.raise_signal(number)
        except BaseException as exc:
            raise ImportError("numpy._core.multiarray failed to import") from exc
        return 0

    monkeypatch.setattr("tlmpc.commands.automaton.run", disguised)
    assert tlmpc.cli.main(["automaton", "G a"]) == code


@pytest.mark.parametrize(("number", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_code_that_handles_errors_does_not_catch_a_signal(
    monkeypatch: pytest.MonkeyPatch, number: signal.Signals, code: int
) -> None:
    # a signal ends the run where it lands: an ``except Exception`` on the way (a reader's or
    # a library's error handling) does not swallow it and carry on
    carried_on: list[str] = []

    def handles_errors(*args: object) -> int:
        try:
            signal.raise_signal(number)
        except Exception:
            carried_on.append("caught as an error")
        return 0

    monkeypatch.setattr("tlmpc.commands.automaton.run", handles_errors)
    assert tlmpc.cli.main(["automaton", "G a"]) == code
    assert carried_on == []
