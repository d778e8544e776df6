"""A deadline's ``time`` in ``summary.json`` is when the trajectory meets it, however far
the deadline: it is searched on the window's end itself, not taken as ``T - slack`` (which
cancels to nothing once ``T`` dwarfs the run: ``F[0,1e12] b`` read as reached at 0 s).

The reference is the first instant the compiled polyline touches the goal (shapely, on the
trace's own samples), and on a straight trace the entry worked out by hand.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import pytest
import shapely

from tlmpc.pipeline.stages import compile_mission
from tlmpc.verify import verify_document
from tlmpc.verify.trace_input import from_document
from tlmpc.verify.verdict import bound_slacks

GOAL = [[7.0, 7.0], [9.0, 7.0], [9.0, 9.0], [7.0, 9.0]]


def first_entry(trace: dict[str, Any], region: list[list[float]]) -> float:
    """The first time the trace's polyline touches the closed region."""
    shape = shapely.Polygon(region)
    points = trace["points"]
    for (t0, x0, y0), (t1, x1, y1) in itertools.pairwise(points):
        hit = shapely.LineString([(x0, y0), (x1, y1)]).intersection(shape)
        if hit.is_empty:
            continue
        span = max(abs(x1 - x0), abs(y1 - y0))
        along = min(max(abs(x - x0), abs(y - y0)) / span for x, y in shapely.get_coordinates(hit))
        return float(t0 + along * (t1 - t0))
    return float("inf")


@pytest.mark.parametrize("deadline", ["100", "1e9", "1e12", "1e300"])
def test_the_time_of_a_deadline_is_the_entry_however_far_the_deadline(
    tmp_path: Path, deadline: str
) -> None:
    text = (
        "version: 1\nname: far\nworkspace:\n  boundary: {rect: [0, 0, 10, 10]}\n"
        f"regions:\n  b: {GOAL}\n"
        "robot: {start: [1, 1], max_speed: 1}\n"
        f'ltl: "F[0,{deadline}] b"\n'
    )
    result = compile_mission(tmp_path / "m.yaml", text=text)
    (bound,) = result.summary()["bounds"]
    trace = result.artifacts["trace.json"]
    entry = first_entry(trace, GOAL)
    assert bound["time"] == pytest.approx(entry, abs=1e-6)
    assert bound["time"] >= bound["lower_bound"]
    # the tightest deadline met: met at its time exactly
    assert verify_document({**trace, "ltl": f"F[0,{bound['time']!r}] b"}).satisfied


def test_the_verifier_finds_the_time_on_the_window_end() -> None:
    # along y = 0.5 at 1 m/s from x = 0: b = [9, 10] is entered at t = 9 exactly
    square = [[9.0, 0.0], [10.0, 0.0], [10.0, 1.0], [9.0, 1.0]]
    document = {
        "format": "tlmpc.trace/1",
        "points": [[0.0, 0.0, 0.5], [9.5, 9.5, 0.5]],
        "loop_start": None,
        "end": "stay",
        "ltl": "F[0,1e15] b & G(b -> F[0,1e14] !b | G b)",
        "regions": {"b": square},
        "workspace": {"boundary": [[-1, -1], [11, -1], [11, 11], [-1, 11]], "holes": []},
        "boundary": "right",
        "max_speed": 10.0,
    }
    outcome, slacks = bound_slacks(from_document(document), deadlines={0})
    assert outcome == "satisfied"
    assert slacks[0].time == pytest.approx(9.0, abs=1e-9)
    met = {**document, "ltl": f"F[0,{slacks[0].time!r}] b"}
    assert verify_document(met).satisfied  # a deadline met, not one just short of it
    assert slacks[1].time is None  # not asked
