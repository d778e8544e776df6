"""The distance a path keeps from a region's own boundary: an absolute clearance (0.1 s at
max_speed, the default goal depth), never more than the portal fractions it replaces.

Oracles: the insets are checked against their definition on portals whose lengths the test
chooses (plain arithmetic on the ends the test places); the soundness of the shallower
goals and of the clearance is checked end to end by the verifier (which shares no code with
planning or control) on random missions in which regions are both visited and avoided (so
their label boundaries are their own) and on random goals: every trace satisfies its task on
the true regions with a positive robustness, and is certified.
"""

from __future__ import annotations

import math
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import tlmpc
from tlmpc.abstraction.layout import GOAL_DEPTH_TIME
from tlmpc.control.channel import (
    ENTERED_INSET,
    LABEL_INSET,
    PORTAL_INSET,
    ChannelStep,
    _exit_insets,
    label_clearance,
)
from tlmpc.verify import verify_document


def _step(length: float, **flags: Any) -> ChannelStep:
    # counter-clockwise; the exit edge 0 (opposite corner 0) runs from corner 1 (the right
    # end, facing out) to corner 2 (the left end), ``length`` long
    corners = ((0.0, 0.0), (length, 1.0), (0.0, 1.0))
    return ChannelStep(corners=corners, exit_edge=0, **flags)


def test_the_clearance_is_a_tenth_of_a_second_at_max_speed() -> None:
    assert label_clearance(1.0) == pytest.approx(GOAL_DEPTH_TIME)
    assert label_clearance(2.5) == pytest.approx(2.5 * GOAL_DEPTH_TIME)


@pytest.mark.parametrize("length", [0.1, 0.3, 0.5, 1.0, 3.0, 10.0, 40.0])
@pytest.mark.parametrize("clearance", [0.05, 0.1, 0.4])
def test_an_exposed_end_keeps_the_clearance_within_the_fractions(
    length: float, clearance: float
) -> None:
    # the left end (corner 2) lies on a region's own boundary, the right end does not
    step = _step(length, labelled=(False, False, True), clearance=clearance)
    left, right = _exit_insets(step)
    assert right == PORTAL_INSET
    # kept along the portal: the clearance, but at least the portal inset and at most the
    # label inset, as fractions of the portal's length
    kept = left * length
    assert kept >= min(clearance, LABEL_INSET * length) - 1e-12
    assert PORTAL_INSET * length - 1e-12 <= kept <= max(clearance, PORTAL_INSET * length) + 1e-12
    assert left <= LABEL_INSET


@pytest.mark.parametrize("length", [0.2, 1.0, 10.0])
def test_entering_a_label_keeps_the_clearance_at_its_exposed_ends(length: float) -> None:
    both = _step(length, labelled=(False, True, True), entered=True, clearance=0.1)
    left, right = _exit_insets(both)
    assert left == right == max(PORTAL_INSET, min(ENTERED_INSET, 0.1 / length))
    one = _step(length, labelled=(False, True, False), entered=True, clearance=0.1)
    assert _exit_insets(one)[0] == PORTAL_INSET  # the left end is not exposed


@pytest.mark.parametrize("length", [0.2, 1.0, 10.0])
def test_entering_a_label_by_a_wall_keeps_the_clearance_at_both_ends(length: float) -> None:
    step = _step(length, labelled=(False, True, False), entered=True, by_wall=True, clearance=0.1)
    kept = max(PORTAL_INSET, min(ENTERED_INSET, 0.1 / length))
    assert _exit_insets(step) == (kept, kept)


def test_a_clearance_wider_than_the_portal_allows_keeps_the_fractions() -> None:
    # a 10 m clearance on a 10 m portal: a quarter at an exposed end, two fifths at both
    # ends where a label is entered by a wall (the portal keeps its middle)
    step = _step(10.0, labelled=(False, False, True), clearance=10.0)
    assert _exit_insets(step) == (LABEL_INSET, PORTAL_INSET)
    entered = _step(10.0, labelled=(False, False, True), entered=True, by_wall=True, clearance=10.0)
    assert _exit_insets(entered) == (ENTERED_INSET, ENTERED_INSET)


def _rect(x: float, y: float, w: float, h: float) -> list[float]:
    return [round(x, 3), round(y, 3), round(x + w, 3), round(y + h, 3)]


@st.composite
def both_polarities(draw: st.DrawFn) -> dict[str, Any]:
    """Example 1's shape on a random map: visit p2, p3, p4 in turn, then return to p1 while
    avoiding p2 and p3 (so p2 and p3 label their own shapes), at a random speed."""
    size = draw(st.sampled_from([8.0, 12.0, 30.0]))
    q = size / 2.0

    def box(x0: float, y0: float) -> list[float]:
        w = draw(st.floats(0.15, 0.8)) * q * 0.8
        h = draw(st.floats(0.15, 0.8)) * q * 0.8
        u, v = draw(st.floats(0.0, 1.0)), draw(st.floats(0.0, 1.0))
        return _rect(x0 + 0.1 * q + u * (0.8 * q - w), y0 + 0.1 * q + v * (0.8 * q - h), w, h)

    p1 = box(0.0, 0.0)
    start = [(p1[0] + p1[2]) / 2.0, (p1[1] + p1[3]) / 2.0]
    return {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, size, size]}},
        "regions": {
            "p1": {"rect": p1},
            "p2": {"rect": box(0.0, q)},
            "p3": {"rect": box(q, q)},
            "p4": {"rect": box(q, 0.0)},
        },
        "robot": {"start": start, "max_speed": draw(st.sampled_from([0.5, 1.0, 3.0]))},
        "ltl": "F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))",
    }


def _verified(compiled: tlmpc.Compiled) -> None:
    verdict = verify_document(dict(compiled.artifacts["trace.json"]))
    assert verdict.outcome == "satisfied"
    assert verdict.robustness is not None
    assert verdict.robustness > 0.0
    assert verdict.certified, verdict.certificate


@pytest.mark.slow
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mission=both_polarities())
def test_regions_visited_and_avoided_keep_a_positive_certified_robustness(
    mission: dict[str, Any],
) -> None:
    _verified(tlmpc.compile(mission))


@pytest.mark.slow
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    rooms=st.lists(st.floats(1.0, 9.0), min_size=2, max_size=3),
    speed=st.sampled_from([0.5, 1.0, 3.0]),
    radius=st.sampled_from([0.0, 0.2]),
)
def test_goals_at_the_default_depth_keep_a_positive_certified_robustness(
    rooms: list[float], speed: float, radius: float
) -> None:
    # square goals of random sizes in a row, from small (a quarter of the inradius is the
    # depth) to large (0.1 s at max_speed is)
    regions = {}
    x = 1.0
    for k, side in enumerate(rooms):
        regions[f"g{k}"] = {"rect": _rect(x, 1.0, side, side)}
        x += side + 1.0
    robot: dict[str, Any] = {"start": [0.5, 0.5], "max_speed": speed}
    if radius:
        robot["radius"] = radius
    mission = {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, math.ceil(x) + 1.0, 12.0]}},
        "regions": regions,
        "robot": robot,
        "task": ["visit " + " then ".join(regions)],
    }
    _verified(tlmpc.compile(mission))
