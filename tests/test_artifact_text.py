"""The artifact writer's text is what ``json.dumps`` writes, document by document.

``artifact_texts`` encodes a large value held by several documents under the same key once; the
oracle is the plain definition: each document encoded on its own by the standard library
(compact with sorted keys, indented when short, non-finite floats as strings).
"""

from __future__ import annotations

import json
import math
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.io.artifacts import INDENT_BELOW, _finite, artifact_texts, dumps


def _reference(document: Any) -> str:
    """The definition: the standard library's encoder, as the writer promises to call it."""
    try:
        text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
    except ValueError:
        document = _finite(document)
        text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
    if len(text) < INDENT_BELOW:
        text = json.dumps(document, indent=2, sort_keys=True, allow_nan=False)
    return text + "\n"


#: Numbers JSON writes differently although Python calls them equal.
_TRICKY = st.sampled_from([0, 0.0, -0.0, 1, 1.0, True, False, None, 2.5])
#: Finite here: a non-finite float sends the whole document the slow way (see _documents).
_SCALARS = st.one_of(
    _TRICKY,
    st.integers(-(10**20), 10**20),
    st.floats(allow_nan=False, allow_infinity=False),
    st.text(max_size=6),
)
_VALUES = st.recursive(
    _SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5),
        st.tuples(inner, inner),
        st.dictionaries(st.sampled_from(["a", "b", "é", "\x00"]), inner, max_size=3),
    ),
    max_leaves=12,
)
#: 360 characters of JSON: 64 items of it make a document long enough to be written compactly.
_FILLER = [i / 7 for i in range(20)]
_KEYS = st.sampled_from(["regions", "format", "vertices", "b", "\u2603"])


@st.composite
def _large(draw: st.DrawFn, item: st.SearchStrategy[Any]) -> Any:
    """A value at least as large as a shared one (dict or list of 64+ items), long enough
    to be written compactly."""
    drawn = draw(st.lists(item, min_size=1, max_size=8))
    size = draw(st.integers(64, 70))
    items = [[drawn[i % len(drawn)], _FILLER] for i in range(size)]
    if draw(st.booleans()):
        return items
    return {f"r{i}": value for i, value in enumerate(items)}


@st.composite
def _documents(draw: st.DrawFn) -> dict[str, Any]:
    """Documents that hold large values, often equal ones (same data, or equal in Python's
    sense but not in JSON's: 1 and 1.0, 0.0 and -0.0) under the same keys."""
    base = draw(_large(_VALUES))
    documents: dict[str, Any] = {}
    for name in ("mission.json", "abstraction.json", "trace.json"):
        document: dict[Any, Any] = draw(st.dictionaries(_KEYS, _VALUES, max_size=3))
        choice = draw(st.integers(0, 4))
        if choice == 0:
            document["regions"] = base  # the very same object
        elif choice == 1:
            document["regions"] = json.loads(json.dumps(base, allow_nan=True))  # a copy
        elif choice == 2:  # equal for ==, not for JSON: numbers of another type or sign
            document["regions"] = _retyped(base)
        elif choice == 3:
            document["regions"] = draw(_large(_VALUES))
        documents[name] = document
    if draw(st.booleans()):  # keys that are not text (sorted as numbers, written as text)
        documents["verdict.json"] = {2: base, 10: draw(_VALUES), 1.5: "x"}
    if draw(st.booleans()):
        documents["controllers.json"] = draw(st.lists(_VALUES, max_size=3))
    if draw(st.integers(0, 7)) == 0:  # JSON has no such numbers: written as text
        documents["trace.json"]["end"] = draw(st.sampled_from([math.inf, -math.inf, math.nan]))
    return documents


def _retyped(value: Any) -> Any:
    if value is True or value is False:
        return int(value)
    if isinstance(value, int):
        return float(value) if abs(value) < 2**53 else value
    if isinstance(value, float) and value == 0.0:
        return -value
    if isinstance(value, dict):
        return {k: _retyped(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_retyped(v) for v in value]
    return value


@pytest.mark.slow
@given(_documents())
def test_each_text_is_the_documents_own_encoding(documents: dict[str, Any]) -> None:
    texts = dict(artifact_texts(documents))
    assert texts == {name: _reference(document) for name, document in documents.items()}
    assert all(dumps(document) == texts[name] for name, document in documents.items())


def test_equal_in_python_but_not_in_json_is_encoded_apart() -> None:
    one = {f"r{i}": [[1, 0.0], [True, 2]] for i in range(2000)}
    other = {f"r{i}": [[1.0, -0.0], [1, 2.0]] for i in range(2000)}
    assert one == other
    texts = dict(artifact_texts({"a.json": {"regions": one}, "b.json": {"regions": other}}))
    assert '"r0":[[1,0.0],[true,2]]' in texts["a.json"]
    assert '"r0":[[1.0,-0.0],[1,2.0]]' in texts["b.json"]


def test_shared_value_with_a_non_finite_number_is_written_as_text() -> None:
    regions = {f"r{i}": [float(i), math.inf] for i in range(2000)}
    texts = dict(
        artifact_texts({"a.json": {"regions": regions}, "b.json": {"regions": regions, "n": 1}})
    )
    assert texts["a.json"] == _reference({"regions": regions})
    assert '"r5":[5.0,"inf"]' in texts["b.json"]


def test_a_document_holding_itself_fails_as_it_always_did() -> None:
    loop: list[Any] = [1.5] * 100
    loop.append(loop)
    for document in ({"a": loop}, {"a": loop, "b": math.nan}, loop):
        with pytest.raises(RecursionError):
            dumps(document)
        with pytest.raises(RecursionError):
            dict(artifact_texts({"a.json": document, "b.json": {"a": loop}}))
