"""The verifier's continuous-time semantics on hand-made traces, both conventions."""

from __future__ import annotations

import ast
import io
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main
from tlmpc.verify import verdict_to_json, verify_document

ROOT = Path(__file__).resolve().parents[2]
A = [[0, 0], [2, 0], [2, 2], [0, 2]]
B = [[2, 0], [4, 0], [4, 2], [2, 2]]
C = [[5, 3], [6, 3], [6, 4], [5, 4]]
WORKSPACE = {
    "boundary": [[0, 0], [10, 0], [10, 10], [0, 10]],
    "holes": [[[7, 7], [8, 7], [8, 8], [7, 8]]],
}


def trace(
    points: Sequence[Sequence[float]],
    ltl: str,
    loop_start: int | None = None,
    boundary: str = "right",
    end: str | None = None,
) -> dict[str, Any]:
    """A trace document; without a loop it stays at its last point unless ``end`` says."""
    if end is None:
        end = "loop" if loop_start is not None else "stay"
    return {
        "end": end,
        "format": "tlmpc.trace/1",
        "ltl": ltl,
        "regions": {"a": A, "b": B, "c": C},
        "workspace": WORKSPACE,
        "boundary": boundary,
        "max_speed": 1.0,
        "points": points,
        "loop_start": loop_start,
    }


HANDOVER = [[0, 1, 1], [1, 3, 1]]  # from inside a straight into b across their shared edge


@pytest.mark.parametrize(
    ("ltl", "right", "closed"),
    [
        ("a U b", True, True),
        ("G !(a & b)", True, False),  # at the handover point the closed regions overlap
        ("F b", True, True),
        ("G (a | b)", True, True),
        ("a", True, True),
        ("F G b", True, True),
        ("G a", False, False),
        ("!b U a", True, True),
        ("(a & !b) U b", True, True),  # b holds at the handover instant itself
        ("(a & !b) U (b & !a)", True, False),  # closed: the handover point is in a and b
    ],
)
def test_handover(ltl: str, right: bool, closed: bool) -> None:
    for convention, expected in (("right", right), ("closed", closed)):
        verdict = verify_document(trace(HANDOVER, ltl), boundary=convention)
        assert verdict.satisfied is expected, (ltl, convention)


def test_touching_a_region_at_one_point() -> None:
    # the segment touches c's corner (5, 3) and nothing else of c
    points = [[0, 4, 4], [2, 6, 2]]
    assert verify_document(trace(points, "G !c"), boundary="right").satisfied
    assert not verify_document(trace(points, "G !c"), boundary="closed").satisfied


def test_point_in_a_then_open_b() -> None:
    # starts on a's edge shared with b, then moves into b: under the closed convention the
    # start instant is in a and b, and b holds right after, so a U b holds via b at once;
    # F(a & !b) needs a moment in a but not b, which never comes
    points = [[0, 2, 1], [1, 3, 1]]
    assert verify_document(trace(points, "a U b"), boundary="closed").satisfied
    assert not verify_document(trace(points, "F(a & !b)"), boundary="closed").satisfied
    assert not verify_document(trace(points, "F a"), boundary="right").satisfied
    assert verify_document(trace(points, "F a"), boundary="closed").satisfied


def test_finite_trace_stays_at_its_last_point() -> None:
    points = [[0, 1, 1], [1, 3, 1]]
    assert verify_document(trace(points, "F G b")).satisfied
    assert not verify_document(trace(points, "G F a")).satisfied


def test_lasso_repeats_its_loop() -> None:
    # a, then loop between b and free space forever
    points = [[0, 1, 1], [1, 3, 1], [2, 3, 3], [3, 3, 1]]
    assert verify_document(trace(points, "G F b & G F !b", loop_start=1)).satisfied
    assert not verify_document(trace(points, "F G b", loop_start=1)).satisfied
    assert not verify_document(trace(points, "G F a", loop_start=1)).satisfied


def test_counterexample_says_where_and_when() -> None:
    points = [[0, 4.5, 3.5], [1, 5.5, 3.5], [2, 6.5, 3.5]]
    verdict = verdict_to_json(verify_document(trace(points, "G !c")))
    assert not verdict["satisfied"]
    example = verdict["counterexample"]
    assert example["conjunct"] == "G !c"
    assert example["time"] == pytest.approx(0.5)
    assert example["position"] == pytest.approx([5.0, 3.5])
    assert "entered c at t=0.5 s" in example["message"]


def test_never_reached() -> None:
    verdict = verdict_to_json(verify_document(trace(HANDOVER, "F c & F b")))
    assert "`c` never holds" in verdict["counterexample"]["message"]


def test_entering_a_hole_is_always_a_violation() -> None:
    points = [[0, 6.5, 7.5], [1, 7.5, 7.5]]
    verdict = verdict_to_json(verify_document(trace(points, "true")))
    assert not verdict["satisfied"]
    assert "entered a hole" in verdict["workspace_violation"]["message"]
    assert verdict["workspace_violation"]["time"] == pytest.approx(0.5)


def test_leaving_the_workspace_is_a_violation() -> None:
    verdict = verdict_to_json(verify_document(trace([[0, 9, 9], [1, 11, 9]], "true")))
    assert "left the workspace" in verdict["workspace_violation"]["message"]


def test_robustness_and_certificate() -> None:
    # deep inside a, slowly: robust and certified
    points: list[list[float]] = [[0, 1, 1], [0.1, 1.01, 1]]
    verdict = verify_document(trace(points, "G a"))
    assert verdict.robustness == pytest.approx(0.99, abs=1e-9)
    assert verdict.certified
    # a U b across a shared edge: robustness 0 at the boundary, never certified
    assert not verify_document(trace(HANDOVER, "a U b")).certified


def test_verdict_schema() -> None:
    from tlmpc.io.schema_check import validation_errors

    document = verdict_to_json(verify_document(trace(HANDOVER, "G !c")))
    assert validation_errors(document, "verdict") == []


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(["verify", *argv], out=out, err=err), out.getvalue(), err.getvalue()


def test_cli_exit_codes(tmp_path: Path) -> None:
    good = tmp_path / "good.json"
    good.write_text(json.dumps(trace(HANDOVER, "F b")))
    assert run(str(good))[0] == 0
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(trace(HANDOVER, "G a")))
    code, out, _ = run(str(bad))
    assert code == 1
    assert "VIOLATED" in out
    assert "violation: " in out
    code, out, _ = run(str(bad), "--json")
    assert json.loads(out)["result"]["satisfied"] is False


@pytest.mark.parametrize(
    ("points", "code"),
    [
        ([], "V002"),
        ([[0, 1, 1], [0, 2, 1]], "V020"),
        ([[0, 1, 1], [1, 2, 1], [0.5, 2, 2]], "V005"),
        ([[0, 1, 1], [1, float("nan"), 1]], "V003"),
        ([[0, 1], [1, 2]], "V002"),
        ("nope", "V002"),
    ],
)
def test_garbage_traces_exit_2(tmp_path: Path, points: Any, code: str) -> None:
    path = tmp_path / "t.json"
    path.write_text(json.dumps(trace(points, "F b"), allow_nan=True))
    status, _, err = run(str(path))
    assert status == 2
    assert f"error[{code}]" in err


def test_unknown_region_and_bad_format(tmp_path: Path) -> None:
    path = tmp_path / "t.json"
    path.write_text(json.dumps(trace(HANDOVER, "F kitchen")))
    status, _, err = run(str(path))
    assert (status, "error[V007]" in err) == (2, True)
    path.write_text(json.dumps({"format": "something/1"}))
    assert run(str(path))[0] == 2
    path.write_text("{not json")
    assert run(str(path))[0] == 2


def test_csv_with_mission(tmp_path: Path) -> None:
    mission = ROOT / "specs" / "example1.yaml"
    log = tmp_path / "robot.csv"
    log.write_text("t,x,y\n0,1.5,1.5\n10,1.5,7.5\n")  # from p1 up into p2, then stays
    status, out, _ = run(str(log), "--mission", str(mission))
    assert status == 4  # a log that may go on: p3, p4 and p1 may still come
    assert "inconclusive" in out
    status, out, _ = run(str(log), "--mission", str(mission), "--assume-stay")
    assert status == 1  # p2 visited but not p3, p4
    assert "never holds" in out or "does not hold" in out
    assert run(str(log))[0] == 2  # a CSV needs --mission
    log.write_text("t,x,y\n0,1,1\n1,2\n")
    status, _, err = run(str(log), "--mission", str(mission))
    assert status == 2
    assert ":3:" in err  # the CSV line of the bad row


def test_verify_imports_nothing_from_the_planner() -> None:
    forbidden = (
        "tlmpc.automata",
        "tlmpc.planning",
        "tlmpc.control",
        "tlmpc.simulate",
        "tlmpc.abstraction",
        "tlmpc.pipeline.stages",
    )
    for path in (ROOT / "tlmpc" / "verify").glob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            for name in names:
                assert not name.startswith(forbidden), f"{path.name} imports {name}"
