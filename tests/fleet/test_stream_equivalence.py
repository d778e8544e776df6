"""The streamed verifier (chunks, kept samples) against the whole-log verifier: the same
verdict, the same conjunct verdicts and progress, the same violations (times, places and
durations), for random trajectories over regions that touch, overlap and share edges, random
formulas from the whole language, both conventions and every ending."""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from strategies import formulas

from tlmpc.base.errors import UsageError
from tlmpc.fleet.stream import Reducer, verify_log
from tlmpc.ltl.printer import to_text
from tlmpc.verify import verdict_to_json, verify_document

REGIONS = {
    "a": [[1.0, 1.0], [4.0, 1.0], [4.0, 4.0], [1.0, 4.0]],
    "b": [[4.0, 1.0], [7.0, 1.0], [7.0, 3.0], [4.0, 3.0]],  # shares an edge with a
    "c": [[3.0, 3.0], [6.0, 3.0], [4.5, 6.0]],  # overlaps a and b
    "d": [[6.0, 5.0], [8.5, 5.0], [8.5, 7.5], [6.0, 7.5]],
}
WORKSPACE = {
    "boundary": [[0.0, 0.0], [10.0, 0.0], [10.0, 8.0], [0.0, 8.0]],
    "holes": [[[8.0, 1.0], [9.0, 1.0], [9.0, 2.0], [8.0, 2.0]]],
}


def document(ltl: str, convention: str, radius: float) -> dict[str, Any]:
    return {
        "format": "tlmpc.trace/1",
        "ltl": ltl,
        "regions": REGIONS,
        "workspace": WORKSPACE,
        "boundary": convention,
        "max_speed": 50.0,
        "radius": radius,
        "points": [],
        "loop_start": None,
    }


coordinate = st.one_of(
    st.integers(-2, 22).map(lambda k: k / 2.0),  # on edges and corners often
    st.floats(-0.5, 10.5, allow_nan=False),
)


@st.composite
def walks(draw: st.DrawFn) -> np.ndarray:
    """A trajectory: waypoints joined by densely sampled straight runs (the shape of a log)."""
    waypoints = draw(st.lists(st.tuples(coordinate, coordinate), min_size=1, max_size=6))
    per_leg = draw(st.integers(1, 40))
    points = [np.asarray(waypoints[0], dtype=float)]
    for start, end in itertools.pairwise(waypoints):
        s, e = np.asarray(start), np.asarray(end)
        for k in range(1, per_leg + 1):
            points.append(s + (e - s) * k / per_leg)
    xy = np.vstack(points)
    gaps = draw(st.lists(st.floats(0.01, 2.0), min_size=len(xy), max_size=len(xy)))
    t = np.cumsum(gaps)
    return np.column_stack([t, xy])


def comparable(verdict: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in verdict.items() if k not in ("robustness", "certificate", "stats")}


def write_csv(path: Path, samples: np.ndarray) -> None:
    with open(path, "w", encoding="utf-8") as stream:
        stream.write("t,x,y\n")
        np.savetxt(stream, samples, fmt="%.17g", delimiter=",")


@pytest.mark.slow
@settings(
    max_examples=max(40, settings().max_examples * 3 // 4),  # 150 in CI
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    samples=walks(),
    formula=formulas(max_leaves=6),
    convention=st.sampled_from(["right", "closed"]),
    ending=st.sampled_from(["open", "stay", "loop"]),
    radius=st.sampled_from([0.0, 0.0, 0.3]),
    block=st.sampled_from([16, 64, 1 << 22]),
)
def test_streamed_equals_whole(
    tmp_path: Path,
    samples: np.ndarray,
    formula: Any,
    convention: str,
    ending: str,
    radius: float,
    block: int,
) -> None:
    ltl = to_text(formula)
    base = document(ltl, convention, radius)
    path = tmp_path / "log.csv"
    write_csv(path, samples)
    middle = float(samples[len(samples) // 2, 0] - samples[0, 0])  # from the log's start
    loop_from = middle if ending == "loop" else None
    stay = ending == "stay"
    refused: list[str] = []
    try:
        whole = verify_document(
            {**base, "points": samples.tolist()}, assume_stay=stay, loop_from=loop_from
        )
    except UsageError as exc:
        refused = [d.code for d in exc.diagnostics]
    if refused:
        with pytest.raises(UsageError) as caught:
            verify_log(path, base, assume_stay=stay, loop_from=loop_from, block_bytes=block)
        assert [d.code for d in caught.value.diagnostics] == refused
        return
    streamed = verify_log(path, base, assume_stay=stay, loop_from=loop_from, block_bytes=block)
    assert comparable(verdict_to_json(streamed.verdict)) == comparable(verdict_to_json(whole))
    assert streamed.samples == len(samples)
    # robustness keeps the sign of the verdict
    rho = streamed.verdict.robustness
    if streamed.verdict.outcome == "satisfied":
        assert rho >= 0
    elif streamed.verdict.outcome == "violated":
        assert rho <= 0


def test_a_still_robot_keeps_two_samples() -> None:
    reducer = Reducer(document("F a", "right", 0.0))
    t = np.arange(10_000, dtype=float)
    reducer.feed(np.column_stack([t, np.full_like(t, 5.0), np.full_like(t, 7.0)]))
    kept = reducer.finish()
    assert kept[:, 0].tolist() == [0.0, 9999.0]


@pytest.mark.parametrize("where", [(1.0, 1.0), (4.0, 2.0), (0.0, 0.0), (8.5, 6.0)])
def test_a_robot_still_on_a_boundary_keeps_two_samples_and_its_departure(
    where: tuple[float, float],
) -> None:
    """On a region's corner, a shared edge, the workspace's corner, an edge: the anchor's disc
    is empty there, and still no sample at the anchor leaves it (the log's samples standing
    still were all kept, so memory grew with the sampling rate)."""
    reducer = Reducer(document("F a", "right", 0.0))
    t = np.arange(10_000, dtype=float)
    still = np.column_stack([t, np.full_like(t, where[0]), np.full_like(t, where[1])])
    away = np.array([[10_000.0, 5.0, 7.0]])
    reducer.feed(np.vstack([still, away]))
    kept = reducer.finish()
    assert kept[:, 0].tolist() == [0.0, 9999.0, 10_000.0]


def test_every_boundary_crossing_keeps_its_segment() -> None:
    # A line through region a sampled every 0.01: the segments that cross x = 1 and x = 4
    # are kept with both ends, the long stretches between are not.
    reducer = Reducer(document("F a", "right", 0.0))
    x = np.linspace(0.5, 4.5, 401)
    reducer.feed(np.column_stack([np.arange(len(x), dtype=float), x, np.full_like(x, 2.0)]))
    kept = reducer.finish()[:, 1]
    for edge in (1.0, 4.0):
        below, above = kept[kept <= edge].max(), kept[kept >= edge].min()
        assert above - below <= 0.01 + 1e-12
    assert len(kept) < 60
