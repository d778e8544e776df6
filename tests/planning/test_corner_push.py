"""The corner push (tlmpc.planning.robust.best_direction), the one implementation the control
stage's vertex velocities and the convex cells' widths share, against two oracles
(tests/oracles/brute_push.py): brute force over directions and the arc that holds the normals.
Drawn cases of one to five unit normals, with repeats and nearly opposite pairs (a sliver
corner); the direction returned attains the value returned."""

from __future__ import annotations

import math

import pytest
from brute_push import arc_push, sampled_push
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.planning.robust import best_direction

SAMPLES = 50_000

angles = st.floats(-math.pi, math.pi, allow_nan=False)


@st.composite
def normals(draw: st.DrawFn) -> list[tuple[float, float]]:
    """One to five unit normals; often one repeated, or one nearly opposite another."""
    turns = draw(st.lists(angles, min_size=1, max_size=5))
    twist = draw(st.sampled_from(["none", "repeat", "opposite"]))
    if twist == "repeat":
        turns.append(turns[0])
    elif twist == "opposite":
        turns.append(turns[0] + math.pi - draw(st.floats(-1e-3, 1e-3)))
    return [(math.cos(t), math.sin(t)) for t in turns]


@settings(max_examples=300, deadline=None)
@given(normals())
def test_the_push_is_the_maximum_over_every_direction(rows: list[tuple[float, float]]) -> None:
    value, (ux, uy) = best_direction(rows)
    # the direction is a unit vector and attains the value
    assert math.hypot(ux, uy) == pytest.approx(1.0, abs=1e-12)
    assert min(ax * ux + ay * uy for ax, ay in rows) == value
    # no sampled direction pushes more (where the push is positive, it is the maximum), and
    # the maximum is within the samples' spacing of the best sample
    sampled = sampled_push(rows, SAMPLES)
    pushed = max(value, 0.0)
    assert max(sampled, 0.0) <= pushed + 1e-12
    assert pushed <= max(sampled, 0.0) + math.pi / SAMPLES + 1e-12
    # the arc's closed form, to rounding
    assert pushed == pytest.approx(arc_push(rows), abs=1e-12)


def test_no_normal_pushes_fully_and_opposite_normals_not_at_all() -> None:
    assert best_direction([]) == (1.0, (1.0, 0.0))
    value, _ = best_direction([(1.0, 0.0), (-1.0, 0.0)])
    assert value == pytest.approx(0.0, abs=1e-15)
    # three normals a third of a turn apart: in no half-plane, the push is at most 0
    third = [(math.cos(t), math.sin(t)) for t in (0.0, 2.0 * math.pi / 3, 4.0 * math.pi / 3)]
    assert best_direction(third)[0] <= 0.0


def test_a_sliver_corner_keeps_its_digits() -> None:
    """Two normals 1e-9 short of opposite: the push is sin(5e-10), to a few ulps (a bisector
    from the normals' sum would lose it to cancellation)."""
    gap = 1e-9
    rows = [(1.0, 0.0), (math.cos(math.pi - gap), math.sin(math.pi - gap))]
    value, _ = best_direction(rows)
    assert value == pytest.approx(math.sin(gap / 2.0), rel=1e-6)
