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
size = st.floats(1.0, 1e3)


def _rectangle(r: tuple[float, float, float, float, int]) -> list[list[float]]:
    x, y, w, h, first = r
    corners = [[x, y], [x + w, y], [x + w, y + h], [x, y + h]]
    return corners[first:] + corners[:first]


#: Simple polygons (a trace's regions must be, as a mission's): rectangles, from any corner.
polygon = st.tuples(coordinate, coordinate, size, size, st.integers(0, 3)).map(_rectangle)


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


BOWTIE = [[0, 0], [12, 8], [12, 0], [0, 8]]  # its edges cross at (6, 4)
SQUARE = [[0, 0], [12, 0], [12, 8], [0, 8]]


@pytest.mark.parametrize(
    ("workspace", "regions", "what"),
    [
        ({"boundary": BOWTIE}, {"a": [[1, 1], [2, 1], [2, 2]]}, "workspace boundary"),
        ({"boundary": SQUARE}, {"a": [[0, 0], [2, 2], [2, 0], [0, 2]]}, "region 'a'"),
        ({"boundary": SQUARE, "holes": [[[3, 3], [5, 5], [5, 3], [3, 5]]]}, {}, "hole 0"),
        (
            {"boundary": SQUARE, "components": [{"boundary": BOWTIE, "holes": []}]},
            {},
            "boundary of component 0",
        ),
        ({"boundary": SQUARE}, {"a": [[1, 1], [2, 2], [3, 3]]}, "region 'a'"),  # zero area
    ],
)
def test_a_self_intersecting_or_flat_polygon_is_V004(
    workspace: dict[str, Any], regions: dict[str, Any], what: str
) -> None:
    """A trace takes the shapes a mission takes: a bow-tie workspace made shapely's overlay
    raise (exit 3), a bow-tie region was silently certified."""
    document = {**_document(regions), "workspace": workspace}
    with pytest.raises(UsageError) as caught:
        from_document(document)
    (diagnostic,) = caught.value.diagnostics
    assert diagnostic.code == "V004"
    assert diagnostic.message.startswith(f"{what}: the polygon ")


def test_verify_refuses_a_bowtie_workspace_with_exit_2(tmp_path: Any) -> None:
    import io
    import json

    from tlmpc.cli import main

    trace = tmp_path / "trace.json"
    document = {**_document({"a": [[1, 1], [2, 1], [2, 2]]}), "workspace": {"boundary": BOWTIE}}
    text = json.dumps(document)
    trace.write_text(text)
    err = io.StringIO()
    assert main(["verify", str(trace)], out=io.StringIO(), err=err) == 2
    # placed at the boundary's value in the file (one line: its column is its offset + 1)
    column = text.index('"boundary": ') + len('"boundary": ') + 1
    assert f"{trace}:1:{column}: error[V004]: workspace boundary: the polygon is self-inters" in (
        err.getvalue()
    )
    assert "Traceback" not in err.getvalue()
