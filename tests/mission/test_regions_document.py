"""The regions' document, built once per compile and shared by three artifacts (kept in the
compilation's memo, tlmpc.base.memo)."""

from __future__ import annotations

import contextlib
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

import tlmpc
from tlmpc.base.memo import memo_scope
from tlmpc.mission.load import load_mission
from tlmpc.mission.model import Polygon, regions_document

ROOT = Path(__file__).resolve().parents[2]

_POINTS = st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3))
_PAIRS = st.lists(
    st.tuples(st.text(min_size=1, max_size=3), st.lists(_POINTS, min_size=3, max_size=5)),
    max_size=6,
    unique_by=lambda pair: pair[0],
)


def _definition(pairs: list[tuple[str, Polygon]]) -> dict[str, list[list[float]]]:
    return {name: [[x, y] for x, y in polygon] for name, polygon in pairs}


@given(_PAIRS, _PAIRS, st.booleans())
def test_the_document_is_always_that_of_the_regions_asked_for(
    first: list[tuple[str, list[tuple[float, float]]]],
    second: list[tuple[str, list[tuple[float, float]]]],
    copies: bool,
) -> None:
    with memo_scope():
        _same_polygons_same_document(first, second, copies)


def _same_polygons_same_document(
    first: list[tuple[str, list[tuple[float, float]]]],
    second: list[tuple[str, list[tuple[float, float]]]],
    copies: bool,
) -> None:
    pairs = [(name, tuple(points)) for name, points in first]
    document = regions_document(pairs)
    assert document == _definition(pairs)
    # the same tuples again: the same document; equal tuples that are other objects, or
    # other regions: a document of their own, equal to the definition
    again = [
        (name, tuple(point for point in polygon) if copies else polygon) for name, polygon in pairs
    ]
    assert regions_document(again) == _definition(pairs)
    if copies and pairs:
        assert again[0][1] is not pairs[0][1]
        assert regions_document(again) is not document
    if not copies:
        assert regions_document(again) is document
    others = [(name, tuple(points)) for name, points in second]
    assert regions_document(others) == _definition(others)
    # one polygon changed in place of the list: never the old document
    if pairs:
        changed = [*pairs[:-1], (pairs[-1][0], ((0.5, 0.5), *pairs[-1][1]))]
        regions_document(pairs)
        assert regions_document(changed) == _definition(changed)


def test_a_compile_shares_one_regions_document_among_its_artifacts() -> None:
    path = ROOT / "specs" / "example1.yaml"
    documents = tlmpc.compile(path).artifacts
    regions = documents["mission.json"]["regions"]
    assert documents["trace.json"]["regions"] is regions
    assert documents["abstraction.json"]["regions"] is regions
    mission = load_mission(path)
    assert regions == _definition([(r.name, r.polygon) for r in mission.regions])


def test_outside_a_compilation_each_document_is_built_anew() -> None:
    pairs: list[tuple[str, Polygon]] = [("a", ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)))]
    assert regions_document(pairs) is not regions_document(pairs)


@pytest.mark.parametrize("scoped", [False, True])
def test_equal_polygons_of_other_signs_or_names_get_their_own_document(scoped: bool) -> None:
    with memo_scope() if scoped else contextlib.nullcontext():
        _signs_and_names()


def _signs_and_names() -> None:
    square = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))
    signed = ((-0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))
    assert square == signed  # equal for Python, not for JSON
    assert regions_document([("a", square)]) == {"a": [list(p) for p in square]}
    assert regions_document([("a", signed)])["a"][0] == [-0.0, 0.0]
    assert str(regions_document([("a", signed)])["a"][0][0]) == "-0.0"
    assert list(regions_document([("b", signed)])) == ["b"]
