"""Reading traces: loop on the last sample, certificates, and file-level limits."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main
from tlmpc.verify.trace_input import MAX_CSV_LINE, MAX_CSV_ROWS, from_document

ROOT = Path(__file__).resolve().parents[2]


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def trace(**changes: Any) -> dict[str, Any]:
    document: dict[str, Any] = {
        "format": "tlmpc.trace/1",
        "ltl": "G F a",
        "regions": {"a": [[0, 0], [2, 0], [2, 2], [0, 2]]},
        "workspace": {"boundary": [[-10, -10], [10, -10], [10, 10], [-10, 10]]},
        "boundary": "right",
        "points": [[0, 5, 5], [1, 1, 1], [2, 1, 1.5]],
        "loop_start": None,
        "max_speed": 10.0,
    }
    document.update(changes)
    return document


@pytest.mark.parametrize("loop", [None, 0, 1, 2])
def test_every_documented_loop_start_verifies(tmp_path: Path, loop: int | None) -> None:
    path = tmp_path / "trace.json"
    path.write_text(json.dumps(trace(loop_start=loop)))
    code, out, err = run_cli("verify", str(path), "--json")
    assert code in (0, 1, 4), err
    assert "Traceback" not in err
    verdict = json.loads(out)["result"]
    if loop == 2:  # a loop of the last sample alone is holding it: the robot stays there
        path.write_text(json.dumps(trace(loop_start=None, end="stay")))
        assert json.loads(run_cli("verify", str(path), "--json")[1])["result"] == verdict


@pytest.mark.parametrize("speed", [0, -1.0, 0.5])
def test_a_speed_the_samples_contradict_never_certifies(speed: float) -> None:
    # The samples move at up to ~5.7 per second: max_speed 0.5, 0 or -1 cannot vouch.
    from tlmpc.verify import verdict_to_json, verify_trace

    def certificate(max_speed: float) -> dict[str, Any]:
        document = trace(max_speed=max_speed, end="stay")
        return dict(verdict_to_json(verify_trace(from_document(document)))["certificate"])

    refused = certificate(speed)
    assert refused["certified"] is False
    assert "max_speed" in refused["reason"]
    # A speed the samples respect is taken at its word (the margin then decides).
    assert "max_speed" not in certificate(10.0)["reason"]


def test_max_speed_zero_is_not_certified_by_verify(tmp_path: Path) -> None:
    path = tmp_path / "trace.json"
    path.write_text(json.dumps(trace(max_speed=0, end="stay")))
    code, out, _ = run_cli("verify", str(path))
    assert code == 0
    assert "certified" not in out.replace("not certified", "")


def test_csv_limits_are_checked_before_parsing(tmp_path: Path) -> None:
    mission = str(ROOT / "specs" / "example1.yaml")
    wide = tmp_path / "wide.csv"
    wide.write_text("0," + "1" * (MAX_CSV_LINE + 10) + ",1\n")
    code, _, err = run_cli("verify", str(wide), "--mission", mission)
    assert code == 2
    assert "error[U038]" in err
    # A log past the whole-log limits is streamed in constant memory instead of refused.
    long = tmp_path / "long.csv"
    with long.open("w") as stream:
        stream.writelines(f"{k},1,1\n" for k in range(MAX_CSV_ROWS + 1))
    code, _, err = run_cli("verify", str(long), "--mission", mission)
    assert code in (0, 1, 4), err
    assert f"streamed ({MAX_CSV_ROWS + 1:,} samples, 2 kept)" in err
    ok = tmp_path / "ok.csv"
    ok.write_text("t,x,y\n0,1.5,1.5\n1,1.6,1.6\n")
    code, _, err = run_cli("verify", str(ok), "--mission", mission)
    assert code in (0, 1, 4), err


@pytest.mark.parametrize(
    "text",
    [
        "[" * 100_000 + "]" * 100_000,
        '{"format": "tlmpc.trace/1", "x": ' + "9" * 5000 + "}",
        '{"format": "tlmpc.trace/1", "points": [[0, NaN, Infinity]]}',
    ],
)
def test_hostile_json_traces_are_diagnostics(tmp_path: Path, text: str) -> None:
    path = tmp_path / "trace.json"
    path.write_text(text)
    code, _, err = run_cli("verify", str(path))
    assert code == 2
    assert "Traceback" not in err
    assert "error[" in err


def test_a_robot_that_cannot_move_certifies_nothing() -> None:
    still = trace(points=[[0, 1, 1], [1, 1, 1], [2, 1, 1]], max_speed=0)
    assert from_document(still).max_speed is None


@pytest.mark.parametrize(("x", "y", "clearance"), [(2.0, 0.0, 8.0), (2.0, -10.0, 0.0)])
def test_a_step_a_hair_long_is_measured_without_a_warning(
    x: float, y: float, clearance: float
) -> None:
    """A step of 3.6e-305 (its squared length underflows; the second lies along the wall):
    the workspace robustness is the distance of the point it nearly is (the suite turns a
    numpy warning into a failure)."""
    from tlmpc.verify.verdict import workspace_violations

    hair = trace(points=[[0, x, y], [1, x, y + 3.62409544e-305]])
    violations, robustness = workspace_violations(from_document(hair))
    assert violations == []
    assert robustness == clearance
