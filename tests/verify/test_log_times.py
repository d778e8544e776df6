"""Times in the verifier's words are counted from the log's start, the absolute stamp beside.

The oracle is the same log shifted to start at 0: every message reads the same once the
``(stamp ...)`` notes are taken out, and each stamp is the relative time plus the shift.
"""

from __future__ import annotations

import io
import re
from pathlib import Path
from typing import Any

from hypothesis import example, given, settings
from hypothesis import strategies as st
from robot_data import require_shared

from tlmpc.cli import main
from tlmpc.verify import verdict_to_json, verify_document
from tlmpc.verify.clock import at, seconds

A = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
B = [[6.0, 0.0], [8.0, 0.0], [8.0, 2.0], [6.0, 2.0]]
HAZARD = [[3.5, -1.0], [4.5, -1.0], [4.5, 3.0], [3.5, 3.0]]
STAMP = re.compile(r" \(stamp ([0-9.e+-]+)\)")
STAMPED = re.compile(r"t=([0-9.e+-]+) s \(stamp ([0-9.e+-]+)\)")


def _log(points: list[list[float]], ltl: str) -> dict[str, Any]:
    return {
        "format": "tlmpc.trace/1",
        "ltl": ltl,
        "regions": {"a": A, "b": B, "hazard": HAZARD},
        "workspace": {"boundary": [[-1, -1], [10, -1], [10, 5], [-1, 5]]},
        "boundary": "right",
        "max_speed": 0.5,  # slower than the log: the certificate names the fast pair
        "points": points,
        "loop_start": None,
    }


def _texts(verdict: dict[str, Any]) -> list[str]:
    texts = [v["message"] for v in verdict["violations"]]
    texts += [c["progress"] for c in verdict["conjuncts"]]
    return [*texts, verdict["certificate"]["reason"]]


def test_at_writes_the_stamp_only_for_a_log_not_starting_at_zero() -> None:
    assert at(12.25, 0.0) == "t=12.25 s"
    assert at(1432235512.25, 1432235500.0) == "t=12.25 s (stamp 1432235512.25)"
    assert at(5.0, 5.0) == "t=0 s (stamp 5)"
    assert at(104.124801968961, 47.584) == "t=56.54 s (stamp 104.125)"


@given(
    steps=st.lists(
        st.tuples(
            st.integers(1, 40).map(lambda k: k / 4),  # dyadic: shifting by 2**30 is exact
            st.integers(-4, 36).map(lambda k: k / 4),
        ),
        min_size=1,
        max_size=8,
    ),
    shift=st.sampled_from([47.5, 2.0**30, 1432235500.0]),
    ltl=st.sampled_from(
        [
            "F b & G !hazard & G F a",
            # time bounds: a deadline met or missed, a bounded stay, a response's stretches
            "F[0,6] b & G[0,3] !hazard & G(a -> F[0,1] !a)",
            "F[2,99999999999999999999] b & G(hazard -> F[0,0.5] !hazard)",
        ]
    ),
)
@example(  # a stretch starting at a crossing: placed where the piece is, not interpolated
    steps=[(9.75, -1.0), (7.25, 3.25), (3.75, 8.25), (1.75, 4.0)],
    shift=47.5,
    ltl="F[0,6] b & G[0,3] !hazard & G(a -> F[0,1] !a)",
)
@settings(max_examples=40, deadline=None)
def test_messages_are_relative_to_the_first_sample(
    steps: list[tuple[float, float]], shift: float, ltl: str
) -> None:
    points = [[0.0, 1.0, 1.0]]
    for gap, x in steps:
        points.append([points[-1][0] + gap, x, 1.0])
    at_zero = verdict_to_json(verify_document(_log(points, ltl)))
    shifted_points = [[t + shift, x, y] for t, x, y in points]
    shifted = verdict_to_json(verify_document(_log(shifted_points, ltl)))
    assert shifted["stats"]["start_time"] == shift
    assert at_zero["stats"]["start_time"] == 0.0
    assert shifted["stats"]["duration"] == at_zero["stats"]["duration"]
    for plain, stamped in zip(_texts(at_zero), _texts(shifted), strict=True):
        assert "stamp" not in plain
        assert STAMP.sub("", stamped) == plain
        # each stamp is its relative time plus the log's start
        # (a time bound, "deadline t=6 s", is relative and has no stamp)
        for relative, stamp in STAMPED.findall(stamped):
            assert (
                abs(float(stamp) - (float(relative) + shift))
                <= 1e-3 * max(1.0, float(relative)) + 1e-12 * shift
            )


def test_times_hours_into_a_log_are_written_to_the_tenth() -> None:
    assert seconds(12.25) == "12.25"
    assert seconds(999.94) == "999.9"
    assert seconds(43210.5) == "43210.5"
    assert seconds(-1234.56) == "-1234.6"
    assert seconds(1e23) == "1e+23"  # beyond any log: a bound, in its own form
    assert at(43210.5, 0.0) == "t=43210.5 s"
    # a log twelve hours long: the entry into b is found in it to the tenth of a second
    points = [[0.0, 1.0, 1.0], [43200.0, 1.0, 1.0], [43210.0, 6.0, 1.0], [43220.0, 7.0, 1.0]]
    verdict = verdict_to_json(verify_document(_log(points, "G !b & F[0,43300] b")))
    assert any("entered b at t=43210.0 s" in text for text in _texts(verdict))
    assert any("done at t=43210.0 s, 90 s before the deadline" in text for text in _texts(verdict))


def test_a_deadline_far_away_is_met_at_its_own_time() -> None:
    # the time robustness is the deadline less the instant: 1e20 - 10 is 1e20 in floats
    points = [[0.0, 1.0, 1.0], [10.0, 6.0, 1.0], [20.0, 7.0, 1.0]]
    verdict = verdict_to_json(verify_document(_log(points, "F[0,1e20] b")))
    assert verdict["conjuncts"][0]["progress"].startswith("done at t=10 s, ")


def test_every_stretch_of_a_timed_g_is_listed() -> None:
    # in and out of a fifty times, two seconds each: each stay breaks `a -> F[0,1] !a`
    points = []
    for k in range(50):
        points += [[4.0 * k, 3.0, 1.0], [4.0 * k + 1, 1.0, 1.0], [4.0 * k + 3, 1.0, 1.0]]
    verdict = verdict_to_json(verify_document(_log(points, "G(a -> F[0,1] !a)")))
    assert verdict["verdict"] == "violated"
    assert len(verdict["violations"]) == 50
    assert len({v["time"] for v in verdict["violations"]}) == 50


def test_loop_from_counts_from_the_log_start(tmp_path: Path) -> None:
    trace = tmp_path / "run.csv"
    rows = [(0, 1, 1), (6, 7, 1), (12, 1, 1), (18, 7, 1), (24, 1, 1)]
    trace.write_text("t,x,y\n" + "".join(f"{t + 1000},{x},{y}\n" for t, x, y in rows))
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nworkspace:\n  boundary: {rect: [-1, -1, 10, 5]}\nregions:\n"
        "  a: {rect: [0, 0, 2, 2]}\n  b: {rect: [6, 0, 8, 2]}\nrobot: {start: [1, 1]}\n"
        "task: ['patrol a, b']\n"
    )
    out, err = io.StringIO(), io.StringIO()
    assert (
        main(["verify", str(trace), "--mission", str(mission), "--loop-from", "12"], out, err) == 0
    )
    err = io.StringIO()
    code = main(["verify", str(trace), "--mission", str(mission), "--loop-from", "1012"], out, err)
    assert code == 2
    assert "[0, 24)" in err.getvalue()


def test_the_real_jackal_log_reports_times_from_its_start(tmp_path: Path) -> None:
    # The Jackal's odometry is stamped from 47.58 s (the robot's clock) and lasts 61.18 s:
    # the goal near its last pose is reached about 56 s into the log, never "at 103 s".
    bag = require_shared("bags/jackal_odometry.bag")
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nworkspace:\n  boundary: {rect: [-12, -5, 6, 25]}\nregions:\n"
        "  goal: {rect: [-10, 20, -8, 23]}\nrobot: {start: [0, 0]}\ntask: [visit goal]\n"
    )
    out, err = io.StringIO(), io.StringIO()
    main(["verify", str(bag), "--mission", str(mission)], out, err)
    text = out.getvalue()
    found = re.search(r"done at t=([0-9.]+) s \(stamp ([0-9.]+)\)", text)
    assert found, text
    relative, stamp = float(found[1]), float(found[2])
    assert 0 < relative <= 61.18
    assert abs(stamp - relative - 47.584) < 1e-3
