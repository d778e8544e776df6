"""The speed check behind the certificate, run alike by the verifier, the streamed verifier and
the compile's self-check: a motion at max_speed passes it however finely it is sampled (a chord
across a sliver 1e-9 s long is all rounding), one a millionth faster is refused everywhere.

The oracle is the motion itself: straight runs at a known speed, sampled at drawn times far
from the origin (where rounding is largest) and written as the floats a log would hold.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.fleet.stream import verify_log
from tlmpc.pipeline.stages import _outruns
from tlmpc.verify import verify_document
from tlmpc.verify.robustness import speed_excess

FAR = 1e3  # positions up to this far from the origin, times up to ten times as far
RING = [[-2 * FAR, -2 * FAR], [2 * FAR, -2 * FAR], [2 * FAR, 2 * FAR], [-2 * FAR, 2 * FAR]]


def _document(samples: np.ndarray, max_speed: float) -> dict[str, Any]:
    return {
        "format": "tlmpc.trace/1",
        "ltl": "G a",
        "regions": {"a": RING},
        "workspace": {"boundary": RING},
        "boundary": "right",
        "max_speed": max_speed,
        "points": samples.tolist(),
        "loop_start": None,
    }


@st.composite
def runs(draw: st.DrawFn, *, shortest_gap: float, factor: float) -> tuple[np.ndarray, float]:
    """Samples of a straight run at ``factor`` x max_speed (and max_speed), with gaps of at
    least ``shortest_gap`` s."""
    speed = draw(st.floats(0.1, 5.0))
    start = np.array([draw(st.floats(-FAR, FAR)), draw(st.floats(-FAR, FAR))])
    angle = draw(st.floats(0.0, 2.0 * np.pi))
    heading = np.array([np.cos(angle), np.sin(angle)])
    t0 = draw(st.floats(0.0, 10 * FAR))
    gaps = draw(st.lists(st.floats(shortest_gap, 1e-3), min_size=1, max_size=20))
    offsets = np.concatenate([[0.0], np.cumsum(gaps)])
    # the times and the positions each rounded on their own, as a log holds them
    times = t0 + offsets
    points = start + np.outer(offsets * speed * factor, heading)
    return np.column_stack([times, points]), speed


def _streamed(samples: np.ndarray, document: dict[str, Any]) -> Any:
    """The streamed verifier's answer on ``samples`` written as a CSV log."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "log.csv"
        with open(path, "w", encoding="utf-8") as stream:
            stream.write("t,x,y\n")
            np.savetxt(stream, samples, fmt="%.17g", delimiter=",")
        return verify_log(path, {**document, "points": []}, assume_stay=True)


def _refusals(samples: np.ndarray, speed: float) -> list[bool]:
    """Whether each of the three checks says the samples move faster than ``speed``."""
    document = _document(samples, speed)
    whole = verify_document(document, assume_stay=True).certificate
    streamed = _streamed(samples, document)
    return [
        "faster than max_speed" in whole.reason,
        "faster than max_speed" in streamed.verdict.certificate.reason,
        _outruns(document, speed),
    ]


@settings(max_examples=60, deadline=None)
@given(run=runs(shortest_gap=1e-10, factor=1.0))
def test_a_motion_at_max_speed_is_never_refused(run: Any) -> None:
    samples, speed = run
    assert not speed_excess(samples[:, 0], samples[:, 1:], speed).any()
    assert _refusals(samples, speed) == [False, False, False]


@settings(max_examples=60, deadline=None)
@given(run=runs(shortest_gap=1e-3 / 2, factor=1.0 + 1e-6))
def test_a_motion_a_millionth_faster_is_refused_by_every_check(run: Any) -> None:
    samples, speed = run
    assert speed_excess(samples[:, 0], samples[:, 1:], speed).all()
    assert _refusals(samples, speed) == [True, True, True]


def test_a_chord_across_a_sliver_is_rounding_only() -> None:
    # samples 7e-10 s apart of a compiled trace through a corridor 2e-7 wide (a body of
    # radius 0.4999999 in a corridor 1 wide): a chord 1 + 4.5e-7 times max_speed's, all of it
    # rounding
    samples = np.array(
        [
            [10.678259933800222, 9.499999998182949, 1.9999999975697262],
            [10.678259934491786, 9.499999997873664, 1.9999999981882757],
            [10.678259935161314, 9.499999997574234, 1.9999999987871167],
        ]
    )
    speeds = np.hypot(*np.diff(samples[:, 1:], axis=0).T) / np.diff(samples[:, 0])
    assert speeds.max() > 1.0 + 1e-7  # what a check without the rounding would refuse
    assert not speed_excess(samples[:, 0], samples[:, 1:], 1.0).any()
    assert _refusals(samples, 1.0) == [False, False, False]


def test_a_streamed_log_is_checked_on_every_sample_not_only_the_kept_ones() -> None:
    # along one line at half max_speed but for one gap at twice it: the streamed verifier
    # keeps the ends only (nothing changes between them), whose average speed is allowed
    times = np.array([0.0, 1.0, 2.0, 2.5, 3.5, 4.5])
    xs = np.array([0.0, 0.5, 1.0, 2.0, 2.5, 3.0])
    samples = np.column_stack([times, xs, np.zeros_like(xs)])
    streamed = _streamed(samples, _document(samples, 1.0))
    assert streamed.kept < streamed.samples
    assert "faster than max_speed" in streamed.verdict.certificate.reason
    assert "between t=2 s and t=2.5 s" in streamed.verdict.certificate.reason
    assert not streamed.verdict.certified
