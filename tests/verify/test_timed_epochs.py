"""Time bounds are decided on times counted from the log's first sample, at any epoch.

A log stamped from 1970 (1.7e9 s) or from a simulator's start is the same run as the log
shifted to start at 0: its verdict, its time robustness and every message (the ``(stamp ...)``
notes aside) are those of the shifted log.  Window ends compared in absolute stamps were
rounded to the stamp's precision (2.4e-7 s at 1.7e9, 1.5e-5 s at 1.2e11): a deadline missed
by a few microseconds was met there.  The oracles: the same log started at 0, and for a
deadline reached at a sample, exact rational arithmetic on the relative times.
"""

from __future__ import annotations

import re
from fractions import Fraction
from typing import Any

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedGlobally,
    BoundedUntil,
    Formula,
    Globally,
    Interval,
    Not,
    Or,
    Prop,
)
from tlmpc.ltl.printer import to_text
from tlmpc.verify import verdict_to_json, verify_document
from tlmpc.verify.evaluate import truth_atoms
from tlmpc.verify.semantics import Semantics, Timing

A = [[4.0, 0.0], [6.0, 0.0], [6.0, 2.0], [4.0, 2.0]]
B = [[8.0, 0.0], [10.0, 0.0], [10.0, 2.0], [8.0, 2.0]]
DOCK = [[10.0, 0.0], [12.0, 0.0], [12.0, 8.0], [10.0, 8.0]]
STAMP = re.compile(r" \(stamp [0-9.e+-]+\)")

#: bounds near whole and quarter seconds, none a binary fraction: at an epoch, ``T - b``
#: rounds onto an instant nearby unless it is taken from the first sample
ODD = [0.1, 0.3, 0.7, 1.9999999, 2.0000001, 2.48, 3.33, 4.999995, 9.999995, 10.0000001]
bounds = st.one_of(st.sampled_from(ODD), st.sampled_from([0.0, 0.5, 1.0, 2.0]))
intervals = st.builds(
    lambda low, width: Interval(low, low + width),
    st.sampled_from([0.0, 0.0, 0.1, 0.25, 1.0000001, 2.48]),
    st.one_of(bounds, st.just(float("inf"))),
)


def timed_formulas() -> st.SearchStrategy[Formula]:
    leaves: st.SearchStrategy[Formula] = st.sampled_from([Prop("a"), Prop("b"), Not(Prop("a"))])

    def extend(inner: st.SearchStrategy[Formula]) -> st.SearchStrategy[Formula]:
        return st.one_of(
            st.builds(BoundedEventually, inner, intervals),
            st.builds(BoundedGlobally, inner, intervals),
            st.builds(BoundedUntil, inner, inner, intervals),
            st.builds(lambda a, b: And((a, b)), inner, inner),
            st.builds(lambda a, b: Or((a, b)), inner, inner),
            st.builds(Globally, inner),
        )

    return st.recursive(leaves, extend, max_leaves=4)


#: large offsets: whole seconds up to 2e9, ROS epochs, one beyond 1e11, and halves
offsets = st.one_of(
    st.integers(1, 2 * 10**9).map(float),
    st.sampled_from([1.7e9, 1_700_000_000.5, 1_432_235_500.25, 123_456_789_012.0]),
    st.integers(1, 2**31).map(lambda k: k + 0.5),
    st.floats(1.0, 2e9).map(lambda x: float(np.float32(x))),  # 24 bits: quarters add exactly
)


def _document(points: list[list[float]], ltl: str, ending: str, loop: int | None) -> Any:
    return {
        "format": "tlmpc.trace/1",
        "ltl": ltl,
        "regions": {"a": A, "b": B},
        "workspace": {"boundary": [[-1.0, -1.0], [12.0, -1.0], [12.0, 5.0], [-1.0, 5.0]]},
        "boundary": "right",
        "max_speed": 20.0,
        "points": points,
        "loop_start": loop,
        "end": ending,
    }


def _seen(verdict: dict[str, Any]) -> dict[str, Any]:
    """What a person reads of a verdict, the stamps taken out of the messages."""
    return {
        "verdict": verdict["verdict"],
        "robustness": verdict["robustness"],
        "time_robustness": verdict["time_robustness"],
        "conjuncts": [
            (c["verdict"], STAMP.sub("", c["progress"]), c["time_robustness"])
            for c in verdict["conjuncts"]
        ],
        "violations": [STAMP.sub("", v["message"]) for v in verdict["violations"]],
        "certificate": (
            verdict["certificate"]["margin"],
            STAMP.sub("", verdict["certificate"]["reason"]),
        ),
    }


@given(
    gaps=st.lists(st.sampled_from([0.25, 0.5, 1.0, 2.75, 4.0, 10.0]), min_size=0, max_size=5),
    xs=st.lists(st.sampled_from([0.0, 3.0, 4.0, 5.0, 7.0, 9.0, 11.0]), min_size=6, max_size=6),
    formula=timed_formulas(),
    ending=st.sampled_from(["open", "stay", "loop"]),
    offset=offsets,
)
@example(  # the bug's log: the goal reached at a sample 10 s in, 5e-6 s after the deadline
    gaps=[10.0, 2.0],
    xs=[0.0, 8.0, 9.0, 0.0, 0.0, 0.0],
    formula=BoundedEventually(Prop("b"), Interval(0.0, 9.999995)),
    ending="open",
    offset=123_456_789_012.0,
)
@example(  # a timed G broken on stretches: each stretch at its instant of the log's clock
    gaps=[1.0, 2.75],
    xs=[5.0, 9.0, 5.0, 0.0, 0.0, 0.0],
    formula=Globally(BoundedEventually(Prop("a"), Interval(0.0, 0.1))),
    ending="stay",
    offset=1.7e9,
)
@settings(max_examples=settings().max_examples, deadline=None)
def test_a_log_at_an_epoch_reads_as_the_log_from_zero(
    gaps: list[float], xs: list[float], formula: Formula, ending: str, offset: float
) -> None:
    times = np.concatenate([[0.0], np.cumsum(gaps)]).tolist()
    loop = None
    if ending == "loop":
        assume(len(times) >= 2)
        loop = 0
    stamps = [offset + t for t in times]
    # the offsets whose differences are exact (the rule for logs stamped from an epoch)
    assume(all(s - stamps[0] == t for s, t in zip(stamps, times, strict=True)))
    ltl = to_text(formula)
    at_zero = verdict_to_json(
        verify_document(
            _document([[t, x, 1.0] for t, x in zip(times, xs, strict=False)], ltl, ending, loop)
        )
    )
    shifted = verdict_to_json(
        verify_document(
            _document([[s, x, 1.0] for s, x in zip(stamps, xs, strict=False)], ltl, ending, loop)
        )
    )
    assert _seen(shifted) == _seen(at_zero), ltl
    # every time field is the same instant on the log's own clock
    assert [v["time"] for v in shifted["violations"]] == [
        None if v["time"] is None else offset + v["time"] for v in at_zero["violations"]
    ]


DEADLINES = [
    Fraction(10),
    Fraction(9999995, 10**6),  # 5e-6 s early
    Fraction(99999999, 10**7),  # 1e-7 s early
    Fraction(100000001, 10**7),  # 1e-7 s to spare
    Fraction(1000001, 10**5),  # 1e-5 s to spare
]


@pytest.mark.parametrize("offset", [0.0, 1.7e9, 1_700_000_000.5, 123_456_789_012.0])
@pytest.mark.parametrize("written", DEADLINES)
def test_a_deadline_at_a_sample_is_decided_exactly(offset: float, written: Fraction) -> None:
    # the robot reaches the dock (x = 10) at a sample, exactly 10 s after the first one
    deadline = float(written)
    points = [[offset, 0.0, 1.0], [offset + 10.0, 10.0, 1.0], [offset + 12.0, 11.0, 1.0]]
    document = {
        "format": "tlmpc.trace/1",
        "ltl": f"F[0,{deadline!r}] dock",
        "regions": {"dock": DOCK},
        "workspace": {"boundary": [[0.0, 0.0], [12.0, 0.0], [12.0, 8.0], [0.0, 8.0]]},
        "boundary": "right",
        "points": points,
        "loop_start": None,
    }
    verdict = verdict_to_json(verify_document(document))
    # the oracle: the deadline (the float written) against 10 s, in exact rationals
    spare = Fraction(deadline) - 10
    assert verdict["verdict"] == ("satisfied" if spare >= 0 else "violated")
    # the search's precision: 2**-40 of its range (the log's 12 s, the bound and 1 s)
    assert (
        abs(Fraction(verdict["time_robustness"]) - spare)
        <= Fraction(25, 2**40) + abs(spare) / 10**9
    )
    progress = STAMP.sub("", verdict["conjuncts"][0]["progress"])
    if spare >= 0:
        assert progress.startswith(f"done at t=10 s, {float(spare):.4g} s before the deadline")
    else:
        assert progress.startswith("deadline t=")
        assert progress.endswith(f"missed by {float(-spare):.4g} s")


def test_who_broke_first_is_decided_between_the_log_stamps() -> None:
    # At 1.7e9 s a stamp is a multiple of 2.4e-7 s.  The robot enters the lab (forbidden)
    # 1e-7 s before the alarm (which the environment promised never to sound) goes off:
    # the robot broke its guarantee first, and is to blame, though both instants round to
    # one stamp.
    offset = 1.7e9
    document = {
        "format": "tlmpc.trace/1",
        "ltl": "G !lab",
        "regions": {"lab": [[3.9999999, 0.0], [6.0, 0.0], [6.0, 2.0], [3.9999999, 2.0]]},
        "workspace": {"boundary": [[-1.0, -1.0], [10.0, -1.0], [10.0, 3.0], [-1.0, 3.0]]},
        "boundary": "right",
        "points": [[offset, 0.0, 1.0], [offset + 9.0, 9.0, 1.0]],
        "loop_start": None,
        "end": "open",
        "sensors": ["alarm"],
        "assumptions": ["G !alarm"],
        "signals": {"alarm": [[offset, False], [offset + 4.0, True]]},
    }
    verdict = verify_document(document)
    judged = verdict.reactive
    assert judged is not None
    assert judged.robot is not None
    assert judged.environment is not None
    assert (verdict.outcome, judged.blame) == ("violated", "robot")
    assert judged.robot.broken is not None
    assert judged.robot.broken == pytest.approx(3.9999999, abs=1e-12)
    assert judged.environment.broken == 4.0
    data = verdict_to_json(verdict)["reactive"]
    assert data["robot"]["broken_at"] == offset + judged.robot.broken
    assert data["environment"]["elapsed"] == 4.0


def test_the_dense_evaluator_takes_times_from_the_first_instant() -> None:
    word = np.array([[False], [True], [True]])
    with pytest.raises(ValueError, match="first piece's instant"):
        Semantics(
            truth_atoms(word, ["a"]),
            3,
            "stay",
            timing=Timing(np.array([1.7e9, 1.7e9, 1.7e9 + 1.0]), 1.7e9 + 1.0),
        )(BoundedEventually(Prop("a"), Interval(0.0, 1.0)))
