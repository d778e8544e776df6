"""The time robustness search: exact edges for bounds up to the largest float, a task's value
from its conjuncts' own searches, windows on a loop laid out a period past the trace however
long the trace before the loop, and simulate's V040 placed where the run came from.

The expected values are worked out from the definitions (semantics.md, *Time robustness*) on
straight traces whose region entries are exact in binary: a robot moving along ``y = 0.5`` at
1 m/s enters ``b = [9, 10]`` at t = 9 and ``c = [4, 5]`` at t = 4, leaving it at t = 5.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tlmpc.base.errors import UsageError
from tlmpc.commands.simulate import _verify_run
from tlmpc.verify import verify_document
from tlmpc.verify.dense import _range_reduce


def square(x0: float, x1: float) -> list[list[float]]:
    return [[x0, 0.0], [x1, 0.0], [x1, 1.0], [x0, 1.0]]


def straight(ltl: str) -> dict[str, Any]:
    """From (0, 0.5) at t = 0 to (9.5, 0.5) at t = 9.5 (1 m/s), then staying in b."""
    return {
        "format": "tlmpc.trace/1",
        "points": [[0.0, 0.0, 0.5], [9.5, 9.5, 0.5]],
        "loop_start": None,
        "end": "stay",
        "ltl": ltl,
        "regions": {"a": square(0.0, 1.0), "b": square(9.0, 10.0), "c": square(4.0, 5.0)},
        "workspace": {"boundary": [[-1, -1], [11, -1], [11, 11], [-1, 11]], "holes": []},
        "boundary": "right",
        "max_speed": 10.0,
    }


@pytest.mark.parametrize(
    ("ltl", "expected"),
    [
        # satisfied: the deadline's slack, however large (the search's midpoint and its end
        # once overflowed or rounded past 2**53 s)
        ("F[0,1e308] b", 1e308 - 9.0),
        ("F[0,1.7976931348623157e308] b", 1.7976931348623157e308 - 9.0),
        ("F[0,1e300] a", 1e300),  # a holds at 0: F[0,0] a still holds, F over nothing fails
        ("F[0,1e16] a", 1e16),
        # violated: the loosening that stops it (a G[0, B] !b holds when B < 9)
        ("G[0,1e308] !b", -(1e308 - 9.0)),
        ("!F[0,1e308] b", -(1e308 - 9.0)),
        ("G[0,20] !b", -11.0),
    ],
)
def test_bounds_up_to_the_largest_float(ltl: str, expected: float) -> None:
    got = verify_document(straight(ltl)).time_robustness
    assert got is not None
    assert math.isfinite(got)
    assert got == pytest.approx(expected, rel=1e-9, abs=1e-6)


@pytest.mark.parametrize(
    ("ltl", "expected"),
    [
        ("F[0,20] b & F[0,6] c", min(20.0 - 9.0, 6.0 - 4.0)),
        ("F[0,20] b & G[0,3] !c", min(11.0, 4.0 - 3.0)),
        ("F[0,20] b & G F b", 11.0),  # an untimed conjunct that holds: any amount
        ("F[0,5] b & F[0,3] c", -4.0),  # both must be loosened: by 4 and by 1
        ("F[0,5] b & F[0,30] c", -4.0),  # a satisfied conjunct does not count
        ("F[0,5] b & G F b", -4.0),  # nor does an untimed one that holds
        ("F[0,20] b & G !b", -math.inf),  # an untimed conjunct that fails: no loosening helps
        ("F[0,20] b & (F[0,1] a <-> a)", None),  # a bound under <->: no direction
        ("F[0,5] b & (F[0,1] a <-> a)", None),  # (also in a conjunct that holds)
        # the task's own range (1e300) is 2**40 times the first conjunct's slack and more
        ("F[0,1e16] b & F[0,1e300] a", 1e16 - 9.0),
    ],
)
def test_a_task_is_as_robust_as_its_least_conjunct(ltl: str, expected: float | None) -> None:
    got = verify_document(straight(ltl)).time_robustness
    if expected is None or math.isinf(expected):
        assert got == expected
    else:
        assert got == pytest.approx(expected, rel=1e-9, abs=1e-6)


def short_loop_after_long_prefix(ltl: str) -> dict[str, Any]:
    """1000 s along y = 0.5 from x = -999.5 (a = [0, 1] entered at t = 999.5), then a loop of
    2 ms in and out of a."""
    document = straight(ltl)
    document.update(
        points=[
            [0.0, -999.5, 0.5],
            [1000.0, 0.5, 0.5],
            [1000.001, 1.5, 0.5],
            [1000.002, 0.5, 0.5],
        ],
        loop_start=1,
        end="loop",
        max_speed=2000.0,
        workspace={"boundary": [[-1001, -1], [11, -1], [11, 11], [-1001, 11]], "holes": []},
    )
    return document


@pytest.mark.parametrize(
    ("ltl", "outcome", "expected"),
    [
        # windows reach past the wrap instant by up to the search's horizon (some 3000 s: a
        # million copies of the loop when laid out from the trace's start)
        ("G F[0,1500] a", "satisfied", 1500.0 - 999.5),
        ("G F[0,500] a", "violated", -(999.5 - 500.0)),
        # a holds on [999.5, 1000.0005) (then 1 ms of every 2 ms): G[0,1] a fails until
        # loosened to G[0, 0.5005]
        ("F[0,2000] G[0,1] a", "violated", -(1.0 - 0.5005)),
    ],
)
def test_windows_on_a_short_loop_after_a_long_trace(
    ltl: str, outcome: str, expected: float
) -> None:
    verdict = verify_document(short_loop_after_long_prefix(ltl))
    assert verdict.outcome == outcome
    assert verdict.time_robustness == pytest.approx(expected, abs=1e-6)


def test_a_window_before_a_late_loop_ends_with_the_bound_not_the_period() -> None:
    # Windows starting before the loop are cut at the wrap instant, not a period past their
    # start: until then their right end moves with t + 2.999999999.  a holds only on
    # [4.5, 3.75 + 10/11) (on the way from (5, 3.5) to the loop's rest point (-0.5, 1.5),
    # outside a, from 4.75 on, period 0.5), so `F[0,3-] a` holds on [1.5, 4.659) and
    # `G[0,3-] F[0,3-] a` near t = 1.5: satisfied (the exact dense-time oracle, rational
    # arithmetic on the pieces, agrees; without that end's instants in the window's grid the
    # verifier said violated)
    document = straight("F G[0,2.999999999] F[0,2.999999999] a")
    document.update(
        points=[
            [0.0, 3.5, 1.5],
            [0.25, 3.5, 1.5],
            [0.75, 4.5, 1.5],
            [3.75, 5.0, 3.5],
            [4.75, -0.5, 1.5],
            [5.25, -0.5, 1.5],
        ],
        loop_start=4,
        end="loop",
        regions={"a": [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]], "b": square(2.0, 4.0)},
        max_speed=1e6,
    )
    assert verify_document(document).outcome == "satisfied"


def test_simulate_places_v040_at_the_run_with_its_own_flags() -> None:
    # a window starting 1000 s on meets a million copies of a 1 ms loop: still refused
    document = short_loop_after_long_prefix("G F[1000,1001] a")
    document["points"][2:] = [[1000.0005, 1.5, 0.5], [1000.001, 0.5, 0.5]]
    with pytest.raises(UsageError) as caught:
        _verify_run(document, Path("run-out"))
    (diagnostic,) = caught.value.diagnostics
    assert diagnostic.code == "V040"
    assert diagnostic.location() == "run-out"
    assert diagnostic.hint is not None
    assert "--duration" in diagnostic.hint
    assert "--loop-from" not in diagnostic.hint


@pytest.mark.parametrize("seed", range(20))
def test_range_reduce_against_slices(seed: int) -> None:
    rng = np.random.default_rng(seed)
    values = rng.integers(-5, 5, size=int(rng.integers(1, 300))).astype(np.float64)
    first = rng.integers(0, len(values), size=200)
    last = np.minimum(first + rng.integers(-3, len(values), size=200), len(values) - 1)
    for use_max in (True, False):
        got = _range_reduce(values, first, last, use_max)
        for q in range(len(first)):
            window = values[first[q] : last[q] + 1] if last[q] >= first[q] else values[:0]
            if len(window) == 0:
                assert got[q] == (-np.inf if use_max else np.inf)
            else:
                assert got[q] == (window.max() if use_max else window.min())
