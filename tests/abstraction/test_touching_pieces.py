"""Pieces of free space that touch at a point are connected through it.

A plan may pass through the point where two workspace pieces touch (a vertex passage), so a
region beyond it is reachable: no A011 warning, and the compiled trace (checked by the
verifier, which shares no code with the planner) reaches it through that point.  Pieces
that do not touch keep the warning.
"""

from __future__ import annotations

from typing import Any

import tlmpc
from tlmpc.verify import verify_document


def _two_pieces(second: list[float]) -> dict[str, Any]:
    x0, y0, x1, y1 = second
    return {
        "version": 1,
        "workspace": {
            "boundary": {"rect": [0, 0, 5, 5]},
            "components": [{"boundary": {"rect": [x0, y0, x1, y1]}}],
        },
        "regions": {"goal": {"rect": [x0 + 2, y0 + 2, x0 + 4, y0 + 4]}},
        "robot": {"start": [1, 1], "max_speed": 1.0},
        "task": ["visit goal"],
    }


def test_pieces_touching_at_a_corner_are_connected_through_it() -> None:
    compiled = tlmpc.compile(_two_pieces([5, 5, 10, 10]))
    assert "A011" not in [w.code for w in compiled.warnings]
    trace = compiled.artifacts["trace.json"]
    assert [5.0, 5.0] in [p[1:] for p in trace["points"]]
    assert verify_document(dict(trace)).satisfied


def test_pieces_apart_are_not() -> None:
    compiled = tlmpc.compile(_two_pieces([6, 6, 11, 11]), until="abstraction")
    warnings = [w for w in compiled.warnings if w.code == "A011"]
    assert len(warnings) == 1
    assert "goal" in warnings[0].message
