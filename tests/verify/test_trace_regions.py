"""Reading a trace's regions: all at once when well formed, one by one (with the precise
V004 error) otherwise; either way each region is the array of its own points."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.base.errors import UsageError
from tlmpc.verify.trace_input import from_document

coordinate = st.floats(-1e6, 1e6, allow_nan=False)
polygon = st.lists(st.tuples(coordinate, coordinate).map(list), min_size=3, max_size=7)


def _document(regions: dict[str, Any]) -> dict[str, Any]:
    return {
        "format": "tlmpc.trace/1",
        "ltl": "true",
        "regions": regions,
        "points": [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
    }


@pytest.mark.slow
@given(st.dictionaries(st.from_regex(r"[a-z][a-z0-9_]{0,5}", fullmatch=True), polygon))
def test_regions_are_their_points(regions: dict[str, list[list[float]]]) -> None:
    read = from_document(_document(regions)).regions
    assert list(read) == list(regions)
    for name, points in regions.items():
        assert read[name].shape == (len(points), 2)
        assert np.array_equal(read[name], np.asarray(points, dtype=np.float64))


NOT_A_POLYGON = "region 'b' is not a polygon (at least 3 [x, y] points)"


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ([[0, 0], [1, 0]], NOT_A_POLYGON),
        ([[0, 0], [1, 0], [1, math.inf]], "region 'b' has a non-finite coordinate"),
        ([[0, 0], [1, 0, 2], [1, 1]], "region 'b' is not a list of [x, y] points"),
        ([[0, 0, 1], [1, 0, 2], [1, 1, 3]], NOT_A_POLYGON),
        ("abc", "region 'b' is not a list of [x, y] points"),
    ],
)
def test_a_bad_region_is_named(bad: object, message: str) -> None:
    good = [[0, 0], [1, 0], [0, 1]]
    with pytest.raises(UsageError) as caught:
        from_document(_document({"a": good, "b": bad, "c": good}))
    assert caught.value.diagnostics[0].code == "V004"
    assert caught.value.diagnostics[0].message == message


@pytest.mark.parametrize(("end", "outcome"), [("stay", "satisfied"), ("open", "inconclusive")])
def test_a_last_point_on_a_region_boundary(end: str, outcome: str) -> None:
    """Right convention: a robot that stays forever at a point of ``a``'s boundary is in
    ``a`` (its label is where it rests, the closure); a log that just ends there may go on
    into ``a`` or away from it, so ``F a`` is neither satisfied nor violated yet."""
    from tlmpc.verify import verify_document

    document = {
        "format": "tlmpc.trace/1",
        "ltl": "F a",
        "regions": {"a": [[1.0, -1.0], [2.0, -1.0], [2.0, 1.0], [1.0, 1.0]]},
        "points": [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
        "end": end,
    }
    assert verify_document(document).outcome == outcome
