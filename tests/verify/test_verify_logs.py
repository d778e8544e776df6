"""Logs as users record them: open endings, every violation, robustness vs verdict, certificate,
bad samples, and compiled traces."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.cli import main
from tlmpc.verify import verdict_to_json, verify_document

ROOT = Path(__file__).resolve().parents[2]
A = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
B = [[6.0, 0.0], [8.0, 0.0], [8.0, 2.0], [6.0, 2.0]]
OBSTACLE = [[3.5, 3.0], [4.5, 3.0], [4.5, 4.0], [3.5, 4.0]]


def log(points: list[list[float]], ltl: str, **extra: Any) -> dict[str, Any]:
    return {
        "format": "tlmpc.trace/1",
        "ltl": ltl,
        "regions": {"a": A, "b": B, "o": OBSTACLE},
        "workspace": {"boundary": [[-1, -1], [10, -1], [10, 10], [-1, 10]]},
        "boundary": "right",
        "max_speed": 2.0,
        "points": points,
        "loop_start": None,
        **extra,
    }


def lap(start: float) -> list[list[float]]:
    """a -> b -> a along the bottom, 1 m/s."""
    return [[start, 1.0, 1.0], [start + 6.0, 7.0, 1.0], [start + 12.0, 1.0, 1.0]]


TWO_LAPS = lap(0.0) + lap(12.0)[1:]


def test_a_patrol_log_is_inconclusive_with_visit_counts() -> None:
    verdict = verify_document(log(TWO_LAPS, "G F a & G F b & G !o"))
    assert verdict.outcome == "inconclusive"
    reports = {r.conjunct: r for r in verdict.conjuncts}
    assert reports["G F a"].visits == 3
    assert reports["G F b"].visits == 2
    assert reports["G F b"].last_visit == pytest.approx(17.0)
    # b is left at t=7 and entered again at t=17: the longest time without b
    assert reports["G F b"].longest_gap == pytest.approx(10.0)
    assert reports["G !o"].outcome == "inconclusive"
    # the old reading: the robot stays in a forever, never visiting b again
    assert verify_document(log(TWO_LAPS, "G F a & G F b"), assume_stay=True).outcome == "violated"
    # declared loop: the laps repeat forever
    looped = verify_document(log(TWO_LAPS, "G F a & G F b & G !o"), loop_from=12.0)
    assert looped.outcome == "satisfied"


def test_a_done_reach_task_is_satisfied_and_an_entry_is_violated() -> None:
    assert verify_document(log(TWO_LAPS, "F b")).outcome == "satisfied"
    assert verify_document(log(TWO_LAPS, "F (b & F a)")).outcome == "satisfied"
    through = [[0.0, 1.0, 3.5], [2.0, 3.0, 3.5], [4.0, 5.0, 3.5], [6.0, 3.0, 3.5], [8, 5, 3.5]]
    verdict = verify_document(log(through, "G !o & F b & o U b"))
    assert verdict.outcome == "violated"
    entries = [v for v in verdict.violations if v.conjunct == "G !o"]
    # the path crosses o three times: every entry is listed, with its time and place
    assert [v.time for v in entries] == pytest.approx([2.5, 4.5, 6.5])
    assert [v.position for v in entries] == [(3.5, 3.5), (4.5, 3.5), (3.5, 3.5)]
    # o U b fails at once (neither holds at t=0): a second violated conjunct, listed as well
    assert [v.time for v in verdict.violations if v.conjunct == "o U b"] == [0.0]
    assert {r.conjunct: r.outcome for r in verdict.conjuncts}["F b"] == "inconclusive"


@st.composite
def sparse_logs(draw: st.DrawFn) -> list[list[float]]:
    count = draw(st.integers(1, 6))
    coords = st.floats(-0.5, 9.0, allow_nan=False).map(lambda v: round(v, 2))
    points = [[float(i), draw(coords), draw(coords)] for i in range(count)]
    return points


TASKS = ["G !o", "F b", "a U b", "G F a & F b", "!o U b", "G (a -> F b)", "b R !o", "o W a"]


@given(sparse_logs(), st.sampled_from(TASKS), st.sampled_from(["right", "closed"]))
@pytest.mark.parametrize("ending", ["open", "stay"])
def test_robustness_never_contradicts_the_verdict(
    ending: str, points: list[list[float]], task: str, boundary: str
) -> None:
    verdict = verify_document(log(points, task, end=ending), boundary=boundary)
    if verdict.robustness > 0:
        assert verdict.outcome == "satisfied"
    if verdict.robustness < 0:
        assert verdict.outcome == "violated"
    if verdict.outcome == "inconclusive":
        assert verdict.robustness == 0


def test_sparse_log_entering_between_samples() -> None:
    # two samples either side of o: the samples never touch it, the segment crosses it
    points = [[0.0, 3.0, 3.5], [1.0, 5.0, 3.5]]
    verdict = verify_document(log(points, "G !o", end="stay"))
    assert verdict.outcome == "violated"
    assert verdict.robustness < 0
    assert not verdict.certified or verdict.certificate.margin is not None


def test_a_log_faster_than_max_speed_is_never_certified() -> None:
    slow = [[0.0, 1.0, 1.0], [0.1, 1.05, 1.0]]
    assert verify_document(log(slow, "G a", end="stay")).certified
    fast = [[0.0, 1.0, 1.0], [0.01, 1.2, 1.0]]  # 20 m/s, max_speed 2
    verdict = verify_document(log(fast, "G a", end="stay"))
    assert verdict.outcome == "satisfied"
    assert not verdict.certified
    assert "faster than max_speed" in verdict.certificate.reason
    # and a sparse log that could have left a between samples is not certified either
    sparse = [[0.0, 1.0, 1.0], [10.0, 1.1, 1.0]]
    assert not verify_document(log(sparse, "G a", end="stay")).certified


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(["verify", *argv], out=out, err=err), out.getvalue(), err.getvalue()


def test_cli_endings_and_exit_codes(tmp_path: Path) -> None:
    path = tmp_path / "log.json"
    path.write_text(json.dumps(log(TWO_LAPS, "G F a & G F b")))
    code, out, _ = run(str(path))
    assert code == 4
    assert "G F b: inconclusive: visited 2 times, last at t=17 s, longest gap 10 s" in out
    assert run(str(path), "--assume-stay")[0] == 1
    assert run(str(path), "--loop-from", "12")[0] == 0
    code, out, _ = run(str(path), "--json")
    document = json.loads(out)["result"]
    assert document["verdict"] == "inconclusive"
    assert document["ending"] == "open"
    code, _, err = run(str(path), "--loop-from", "99")
    assert (code, "error[V022]" in err) == (2, True)
    code, _, err = run(str(path), "--loop-from", "23.5")
    assert (code, "error[V023]" in err) == (2, True)


def test_csv_logs_with_bad_samples(tmp_path: Path) -> None:
    mission = ROOT / "specs" / "example1.yaml"
    path = tmp_path / "robot.csv"
    cases = {
        "t,x,y\n0,1,1\n1,2,2\n1,2,3\n": ("V020", ":4:"),
        "t,x,y\n0,1,1\n2,2,2\n1,2,3\n": ("V005", ":4:"),
        "t,x,y\n0,1,1\n1,nan,2\n": ("V003", ":3:"),
        "t,x,y\n": ("V002", "no samples"),
    }
    for text, (code, where) in cases.items():
        path.write_text(text)
        status, _, err = run(str(path), "--mission", str(mission))
        assert status == 2, text
        assert f"error[{code}]" in err, (text, err)
        assert where in err, (text, err)
        assert "Traceback" not in err


def test_all_sample_problems_at_once(tmp_path: Path) -> None:
    path = tmp_path / "t.json"
    points = [[0.0, 1, 1], [1.0, 1, 1], [1.0, 1, 2], [0.5, 1, 1], [2.0, 1, 1], [2.0, 1, 1]]
    path.write_text(json.dumps(log(points, "F a")))
    status, _, err = run(str(path))
    assert status == 2
    assert err.count("error[V020]") == 2
    assert err.count("error[V005]") == 1


@pytest.mark.parametrize(
    "spec", ["example1", "example6", "example7", "example8", "patrol", "reach-avoid", "deadline"]
)
def test_compiled_traces_are_satisfied_and_certified(spec: str, tmp_path: Path) -> None:
    from tlmpc.pipeline.stages import TRACE, compile_mission

    # (the verify stage samples a trace again when that makes its certificate hold)
    result = compile_mission(ROOT / "specs" / f"{spec}.yaml", until="verify")
    document = result.compilation.get(TRACE)
    verdict = verdict_to_json(verify_document(dict(document)))
    assert verdict["verdict"] == "satisfied"
    assert verdict["certificate"]["certified"], verdict["certificate"]["reason"]
    assert verdict["ending"] in ("stay", "loop")


def test_robustness_at_a_rounded_boundary_point_keeps_the_label_sign() -> None:
    # (0.21, 0.07) lies on the slanted edge of `slant` mathematically, but rounding puts it a
    # hair outside; under the right convention it carries the label of where the robot goes
    # (inside), so the task `slant` holds and robustness must not be negative
    document = log([[0.0, 0.21, 0.21 / 3], [1.0, 1.0, 2.0]], "slant", end="stay")
    document["regions"]["slant"] = [[0.0, 0.0], [3.0, 1.0], [3.0, 3.0], [0.0, 3.0]]
    verdict = verify_document(document)
    assert verdict.outcome == "satisfied"
    assert verdict.robustness >= 0


def test_the_certificate_covers_the_gap_before_the_last_sample() -> None:
    # at 0.05 m/s (max_speed 0.1) over 10 s the robot may have strayed 0.5 from either sample;
    # the last sample is 0.5 inside a, so leaving a in between cannot be ruled out
    slow = log([[0.0, 1.0, 1.0], [10.0, 1.5, 1.0]], "G a", end="stay", max_speed=0.1)
    verdict = verify_document(slow)
    assert verdict.outcome == "satisfied"
    assert not verdict.certified


def test_an_open_log_ending_on_a_boundary_does_not_know_the_next_label() -> None:
    # the log stops exactly on b's west edge: under the right convention whether it enters b
    # is up to what comes next; under the closed convention the point itself is in b
    points = [[0.0, 5.0, 1.0], [1.0, 6.0, 1.0]]
    assert verify_document(log(points, "F b")).outcome == "inconclusive"
    assert verify_document(log(points, "G !b")).outcome == "inconclusive"
    assert verify_document(log(points, "F b"), boundary="closed").outcome == "satisfied"
    assert verify_document(log(points, "G !b"), boundary="closed").outcome == "violated"


def test_every_workspace_excursion_is_listed() -> None:
    # out through the east side twice (x > 10), back in between
    points = [[0.0, 9.0, 5.0], [1.0, 11.0, 5.0], [2.0, 9.0, 6.0], [3.0, 9.0, 7.0], [4.0, 11.0, 7.0]]
    verdict = verify_document(log(points, "true", end="stay"))
    excursions = [v for v in verdict.violations if v.conjunct == "workspace"]
    assert [v.time for v in excursions] == pytest.approx([0.5, 3.5])
    assert verdict.outcome == "violated"
    assert verdict.robustness < 0


@given(
    st.lists(st.tuples(st.floats(-5, 5), st.floats(-5, 5)), min_size=3, max_size=8, unique=True),
    st.lists(st.tuples(st.floats(-9, 9), st.floats(-9, 9)), min_size=1, max_size=20),
)
def test_direct_edge_distances_match_shapely(
    corners: list[tuple[float, float]], probes: list[tuple[float, float]]
) -> None:
    import warnings

    import numpy as np
    import shapely

    from tlmpc.verify.robustness import _ring_distance

    ring = np.asarray(corners)
    points = np.asarray(probes)
    with warnings.catch_warnings():
        # GEOS divides by a vanishing edge length on near-degenerate rings (a warning, with
        # the right distance).
        warnings.simplefilter("ignore", RuntimeWarning)
        expected = shapely.distance(shapely.LinearRing(ring), shapely.points(points))
    assert np.allclose(_ring_distance(ring, points), expected, atol=1e-9)
