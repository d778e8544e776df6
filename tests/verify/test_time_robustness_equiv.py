"""Time bounds under ``<->`` have no time robustness, wherever the ``<->`` sits, and the
search for them never fails the verdict; a bound outside every ``<->`` keeps its own slack.

Values are worked out from the definitions (semantics.md, *Time bounds* and *Time
robustness*) on a straight trace whose region entries are exact in binary: a robot moving
along ``y = 0.5`` at 1 m/s from x = 0 holds ``a = [0, 1]`` on [0, 1), ``c = [4, 5]`` on [4, 5)
and ``b = [9, 10]`` from 9 on (right-continuous), and stays at x = 9.5.
"""

from __future__ import annotations

from typing import Any

import pytest

from tlmpc.verify import verify_document
from tlmpc.verify.trace_input import from_document
from tlmpc.verify.verdict import bound_slacks


def square(x0: float, x1: float) -> list[list[float]]:
    return [[x0, 0.0], [x1, 0.0], [x1, 1.0], [x0, 1.0]]


def straight(ltl: str) -> dict[str, Any]:
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
    ("ltl", "outcome"),
    [
        # at 0: a, but no c within [0, 1]: false; at 1: neither: true -> F[0,2] holds
        ("F[0,2] (a <-> F[0,1] c)", "satisfied"),
        # at 0 false, and the window [0, 0.5] holds a throughout: never true -> fails
        ("F[0,0.5] (a <-> F[0,1] c)", "violated"),
        # two windows down, under an until: b <-> G[0,2] c holds before 9 (neither does:
        # c lasts 1 s), so the until holds at once throughout [0, 3]; negated, it fails
        ("G[0,3] (a U[0,1] (b <-> G[0,2] c))", "satisfied"),
        ("!G[0,3] (a U[0,1] (b <-> G[0,2] c))", "violated"),
    ],
)
def test_a_bound_under_a_nested_equivalence_has_no_time_robustness(ltl: str, outcome: str) -> None:
    # a larger tightening empties the outer window first, so only the search's smaller
    # steps meet the `<->`: that is where it used to stop with an internal error
    verdict = verify_document(straight(ltl))
    assert verdict.outcome == outcome
    assert verdict.time_robustness is None
    assert [c.time_robustness for c in verdict.conjuncts] == [None]


def test_a_bound_outside_every_equivalence_keeps_its_slack() -> None:
    # c <-> F[0,1] c is true at 0 (neither); b is entered at 9: F[0,20] b holds for 11 s
    # less, the bound inside the `<->` has no direction
    outcome, slacks = bound_slacks(from_document(straight("F[0,20] b & (c <-> F[0,1] c)")))
    assert outcome == "satisfied"
    assert [(s.bound, s.slack) for s in slacks] == [("F[0,20] b", 11.0), ("F[0,1] c", None)]
