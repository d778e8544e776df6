"""One planning entry for every path: margins compose with the closed convention.

A margin turns goal regions into their cores, so regions that share an edge or a corner no
longer touch on the planning mesh; under the closed convention ``F(a & b)`` is then only met
at the shared boundary, which the margin removes.  The plan without the margin exists (the
crossing instant is in both regions), so compile must fall back to it with R008, and the
automaton it writes must be the closed convention's (the rewritten task over the crossing
and start letters).  Oracles: the verifier (shares no code with planning) for the trace, and
the closed rewrite's own definition for what the written automaton must describe.
"""

from __future__ import annotations

from typing import Any

import pytest

import tlmpc
from tlmpc.ltl.parser import parse_ltl
from tlmpc.ltl.printer import to_text
from tlmpc.planning.boundary import POINT, closed_task
from tlmpc.verify import verify_document


def _touching(b: list[float], ltl: str, *, boundary: str, margin: float) -> dict[str, Any]:
    """``a`` = [2, 5] x [1, 5] and ``b`` given: sharing an edge or only a corner with it."""
    return {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, 10, 8]}},
        "regions": {"a": {"rect": [2, 1, 5, 5]}, "b": {"rect": b}},
        "robot": {"start": [1.0, 0.5], "max_speed": 1.0},
        "options": {"boundary": boundary, "margin": margin},
        "ltl": ltl,
    }


EDGE = [5.0, 1.0, 8.0, 5.0]
CORNER = [5.0, 5.0, 8.0, 7.0]


@pytest.mark.parametrize("b", [EDGE, CORNER], ids=["edge", "corner"])
@pytest.mark.parametrize("margin", [0.05, 0.3])
def test_closed_convention_with_a_margin_falls_back_to_a_plan(
    b: list[float], margin: float
) -> None:
    compiled = tlmpc.compile(_touching(b, "F(a & b)", boundary="closed", margin=margin))
    assert [w.code for w in compiled.warnings if w.code == "R008"] == ["R008"]
    verdict = verify_document(dict(compiled.artifacts["trace.json"]))
    assert verdict.satisfied


def test_the_fallback_writes_the_closed_conventions_automaton() -> None:
    """``!b U a`` under closed is rewritten with the point marker; the fallback's automaton
    (the one written) must read it, as the automaton stage's does."""
    ltl = "F(a & b) & (!b U a)"
    compiled = tlmpc.compile(_touching(EDGE, ltl, boundary="closed", margin=0.3))
    assert "R008" in [w.code for w in compiled.warnings]
    automaton = compiled.artifacts["automaton.json"]
    assert POINT in automaton["aps"]
    assert automaton["formula"] == to_text(closed_task(parse_ltl(ltl)))
    # the crossing letter of the shared edge, with the point marker, is one it reads
    assert [POINT, "a", "b"] in automaton["letters"]


def test_right_convention_with_a_margin_keeps_its_answer() -> None:
    """Under the right-continuous convention no instant is in both: still no plan."""
    with pytest.raises(tlmpc.NoPlanError):
        tlmpc.compile(_touching(EDGE, "F(a & b)", boundary="right", margin=0.3))
