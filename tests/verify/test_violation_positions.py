"""A violation's position is where the robot is at the violation's time, under both
boundary conventions.

The oracle is numpy's linear interpolation of the samples at the reported time: no verifier
code.  Under the closed convention the instant a robot leaves a region is still in it, so a
failing stretch begins with an open piece, whose own position (its midpoint) is not where the
robot is when the stretch begins.
"""

from __future__ import annotations

import random
from typing import Any

import numpy as np
import pytest

from tlmpc.verify import verify_document

REGION_A = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]
REGION_B = [[6.0, 0.0], [8.0, 0.0], [8.0, 4.0], [6.0, 4.0]]
WORKSPACE = {"boundary": [[-1.0, -1.0], [11.0, -1.0], [11.0, 5.0], [-1.0, 5.0]], "holes": []}
FORMULAS = ("G a", "G F a", "G !b", "a U b", "G(a | b)", "G F b")
#: random traces drawn per convention
EXAMPLES = 60


def _trace(points: list[list[float]], ltl: str, boundary: str, end: str) -> dict[str, Any]:
    return {
        "format": "tlmpc.trace/1",
        "points": points,
        "loop_start": None,
        "end": end,
        "ltl": ltl,
        "regions": {"a": REGION_A, "b": REGION_B},
        "workspace": WORKSPACE,
        "boundary": boundary,
        "max_speed": 100.0,
    }


def _where(points: list[list[float]], time: float) -> tuple[float, float]:
    samples = np.asarray(points)
    time = min(time, float(samples[-1, 0]))  # a stay holds the last point
    return (
        float(np.interp(time, samples[:, 0], samples[:, 1])),
        float(np.interp(time, samples[:, 0], samples[:, 2])),
    )


def _checked(points: list[list[float]], ltl: str, boundary: str, end: str) -> int:
    verdict = verify_document(_trace(points, ltl, boundary, end))
    count = 0
    for violation in verdict.violations:
        if violation.time is None or violation.position is None:
            continue
        x, y = _where(points, violation.time)
        assert violation.position == pytest.approx((x, y), abs=1e-9), (ltl, boundary, violation)
        count += 1
    return count


@pytest.mark.parametrize("boundary", ["right", "closed"])
def test_leaving_a_region_is_placed_on_its_edge(boundary: str) -> None:
    # in a until it crosses x = 4 at t = 1.5, between the samples at x = 3 and x = 5
    points = [[0.0, 1.0, 2.0], [1.0, 3.0, 2.0], [2.0, 5.0, 2.0], [3.0, 9.0, 2.0]]
    verdict = verify_document(_trace(points, "G a", boundary, "stay"))
    (violation,) = [v for v in verdict.violations if v.conjunct == "G a"]
    assert violation.time == pytest.approx(1.5)
    assert violation.position == pytest.approx((4.0, 2.0))
    verdict = verify_document(_trace(points, "G F a", boundary, "stay"))
    (violation,) = verdict.violations
    assert violation.position == pytest.approx((4.0, 2.0))


@pytest.mark.parametrize("boundary", ["right", "closed"])
def test_random_traces_place_violations_on_the_trajectory(boundary: str) -> None:
    rng = random.Random(20261129)
    checked = 0
    for _ in range(EXAMPLES):
        points, t = [], 0.0
        for _ in range(rng.randint(2, 7)):
            # coarse samples on a few grid values, so that some lie on region edges
            x = rng.choice([0.5, 2.0, 4.0, 5.0, 6.0, 7.0, 9.0, rng.uniform(0.0, 10.0)])
            points.append([t, x, rng.choice([1.0, 2.0, rng.uniform(0.0, 4.0)])])
            t += rng.choice([0.5, 1.0, 2.0])
        for ltl in FORMULAS:
            checked += _checked(points, ltl, boundary, rng.choice(["stay", "open"]))
    assert checked > EXAMPLES  # the draw does reach violations with a place
