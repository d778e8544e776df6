"""The resolution of completeness for a body (docs/semantics.md, "A robot with a body").

A passage wider than the body's diameter by more than six grid steps between straight walls,
and by more than 1 % of (radius + two grid steps) more where its sides are obstacle corners,
is open; one with four grid steps or less to spare is closed (the body cannot pass with the
two grid steps the erosion keeps per side). The grid is recomputed here from its definition
(the power of ten at or below a billionth of the map's extent), the passages are built from
it, and the verdict is the planner's: a plan, or P010 "no trajectory".
"""

from __future__ import annotations

import math
from typing import Any

import pytest

import tlmpc


def _grid(extent: float) -> float:
    return float(10.0 ** math.floor(math.log10(extent * 1e-9)))


def _mission(width: float, radius: float, scale: float, *, posts: bool) -> dict[str, Any]:
    """Two rooms joined by one passage of ``width``: between straight wall ends (a short
    corridor) or between the tips of two wedges (obstacle corners)."""
    lo, hi = 5 * scale - width / 2, 5 * scale + width / 2
    s = scale
    if posts:
        ring = [[0, 0], [4 * s, 0], [5 * s, lo], [6 * s, 0], [10 * s, 0], [10 * s, 10 * s]]
        ring += [[6 * s, 10 * s], [5 * s, hi], [4 * s, 10 * s], [0, 10 * s]]
    else:
        ring = [[0, 0], [4 * s, 0], [4 * s, lo], [6 * s, lo], [6 * s, 0], [10 * s, 0]]
        ring += [[10 * s, 10 * s], [6 * s, 10 * s], [6 * s, hi], [4 * s, hi], [4 * s, 10 * s]]
        ring += [[0, 10 * s]]
    return {
        "version": 1,
        "workspace": {"boundary": ring},
        "regions": {"b": [[8 * s, 4 * s], [9 * s, 4 * s], [9 * s, 6 * s], [8 * s, 6 * s]]},
        "robot": {"start": [2 * s, 5 * s], "max_speed": 1.0, "radius": radius},
        "task": ["visit b"],
    }


def _open(width: float, radius: float, scale: float, *, posts: bool) -> bool:
    codes: list[str] = []
    try:
        tlmpc.compile(_mission(width, radius, scale, posts=posts), until="plan")
    except tlmpc.NoPlanError as refused:
        codes = [d.code for d in refused.diagnostics]
    if codes:
        assert codes[0] == "P010", codes  # "no trajectory", not another failure
        return False
    return True


@pytest.mark.parametrize("scale", [1.0, 100.0])
@pytest.mark.parametrize("body", [0.05, 0.03])
@pytest.mark.parametrize("posts", [False, True])
def test_passages_open_above_the_resolution_and_close_below_it(
    scale: float, body: float, posts: bool
) -> None:
    extent, radius = 10 * scale, body * 10 * scale
    grid = _grid(extent)
    spare = 6 * grid + (0.01 * (radius + 2 * grid) if posts else 0.0)
    # the smallest spare that is promised to open, a hair above it (rounding of the input)
    assert _open(2 * radius + spare * 1.01, radius, scale, posts=posts)
    assert not _open(2 * radius + 4 * grid, radius, scale, posts=posts)
    assert not _open(2 * radius, radius, scale, posts=posts)
