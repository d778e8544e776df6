"""Arrays held in a document until it is written give the text of the plain lists.

The oracle is the simplest writer there is: the plain list built with ``tolist()`` (or, for a
table of values, one item per index), and the standard library's encoder as the writer
promises to call it (``_reference`` below, independent of the writer's code).  The blocks of
rows are made tiny so that every drawn array crosses block boundaries.
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path
from typing import Any
from unittest import mock

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tlmpc.io import arrays
from tlmpc.io.arrays import ArrayList, TableList, plain
from tlmpc.io.artifacts import INDENT_BELOW, artifact_texts, dump_pieces, dumps
from tlmpc.io.outdir import write_artifacts


def _finite(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


def _reference(document: Any) -> str:
    """The definition: the standard library's encoder on the plain document."""
    try:
        text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
    except ValueError:
        document = _finite(document)
        text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
    if len(text) < INDENT_BELOW:
        text = json.dumps(document, indent=2, sort_keys=True, allow_nan=False)
    return text + "\n"


_FLOATS = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.sampled_from([0.0, -0.0, 1e-300, 5e-324, 1.7976931348623157e308, 0.1, 1 / 3]),
)
_SHAPES = (
    st.tuples(st.integers(0, 40))
    | st.tuples(st.integers(0, 40), st.integers(0, 3))
    | st.tuples(st.integers(0, 6), st.integers(0, 3), st.integers(0, 2))  # the encoder's path
)


def _arrays(finite: bool = True) -> st.SearchStrategy[npt.NDArray[Any]]:
    floats = _FLOATS if finite else st.floats()
    return st.one_of(
        hnp.arrays(np.float64, _SHAPES, elements=floats),
        hnp.arrays(np.int64, _SHAPES, elements=st.integers(-(2**63), 2**63 - 1)),
        hnp.arrays(np.int32, _SHAPES, elements=st.integers(-(2**31), 2**31 - 1)),
        # every kind the formatting tells apart: unsigned, narrow floats, booleans
        hnp.arrays(np.uint64, _SHAPES, elements=st.integers(0, 2**64 - 1)),
        hnp.arrays(np.uint8, _SHAPES),
        hnp.arrays(np.float32, _SHAPES, elements=st.floats(width=32, allow_nan=finite is False)),
        hnp.arrays(np.float16, _SHAPES, elements=st.floats(width=16, allow_infinity=not finite)),
        hnp.arrays(np.bool_, _SHAPES),
    )


@st.composite
def _tables(draw: st.DrawFn) -> tuple[list[Any], npt.NDArray[np.int64]]:
    # label sets (lists of names), now and then with an item of another kind among them
    names = st.lists(st.text(max_size=4), max_size=3)
    other = st.integers() | st.none() | st.lists(st.integers() | st.text(max_size=2), max_size=2)
    table = draw(st.lists(names | other if draw(st.booleans()) else names, min_size=1, max_size=6))
    index = draw(hnp.arrays(np.int64, st.integers(0, 60), elements=st.integers(0, len(table) - 1)))
    return table, index


@st.composite
def _documents(draw: st.DrawFn, finite: bool = True) -> tuple[dict[str, Any], dict[str, Any]]:
    """A document with stand-ins, and the same document written the simple way."""
    held: dict[str, Any] = {"format": "x/1", "n": draw(st.integers())}
    simple: dict[str, Any] = dict(held)
    for key in draw(st.lists(st.sampled_from(["a", "b", "vertices", "é"]), unique=True)):
        if draw(st.booleans()):
            array = draw(_arrays(finite))
            held[key] = ArrayList(array)
            simple[key] = array.tolist()
        else:
            table, index = draw(_tables())
            held[key] = TableList(table, index)
            simple[key] = [table[i] for i in index.tolist()]
    if draw(st.booleans()):  # long enough to be written compactly
        held["filler"] = simple["filler"] = [i / 7 for i in range(1200)]
    return held, simple


@given(_documents())
def test_a_document_with_arrays_is_written_as_its_plain_lists(
    pair: tuple[dict[str, Any], dict[str, Any]],
) -> None:
    held, simple = pair
    expected = _reference(simple)
    with mock.patch.object(arrays, "BLOCK_ROWS", 3):
        assert dumps(held) == expected
        assert dict(artifact_texts({"m.json": held})) == {"m.json": expected}
        assert "".join(dump_pieces(held)) == expected
        with tempfile.TemporaryDirectory() as folder:  # the file, written piece by piece
            write_artifacts(Path(folder), {"m.json": held, "plain.json": simple})
            assert (Path(folder) / "m.json").read_bytes() == expected.encode("utf-8")
            assert (Path(folder) / "plain.json").read_bytes() == expected.encode("utf-8")
    assert dumps(held) == expected
    assert plain(held) == simple


@given(_arrays(), st.integers(1, 5))
def test_an_array_is_encoded_as_the_standard_encoder_writes_its_list(
    array: npt.NDArray[Any], block_rows: int
) -> None:
    encoder = json.JSONEncoder(separators=(",", ":"), allow_nan=False)
    expected = json.dumps(array.tolist(), separators=(",", ":"), allow_nan=False)
    with mock.patch.object(arrays, "BLOCK_ROWS", block_rows):
        assert "".join(arrays.encoded_pieces(ArrayList(array), encoder)) == expected
        # a view with strides (a column, every other row) reads as its own list
        if array.ndim == 2:
            view = array[::2, ::-1]
            expected = json.dumps(view.tolist(), separators=(",", ":"), allow_nan=False)
            assert "".join(arrays.encoded_pieces(ArrayList(view), encoder)) == expected


@given(_documents(finite=False))
def test_non_finite_numbers_in_arrays_are_written_as_text(
    pair: tuple[dict[str, Any], dict[str, Any]],
) -> None:
    held, simple = pair
    with mock.patch.object(arrays, "BLOCK_ROWS", 2):
        assert dumps(held) == _reference(simple)
        assert "".join(dump_pieces(held)) == _reference(simple)


def test_arrays_read_like_their_lists() -> None:
    array = np.arange(12, dtype=np.int64).reshape(4, 3)
    held = ArrayList(array)
    assert held == array.tolist()
    assert len(held) == 4
    assert held[1] == [3, 4, 5]
    assert list(held) == array.tolist()
    assert np.asarray(held) is array
    assert np.asarray(held, dtype=np.float64).dtype == np.float64
    labels = TableList([[], ["a"], ["a", "b"]], np.array([2, 0, 1, 1]))
    assert labels == [["a", "b"], [], ["a"], ["a"]]
    assert labels[0] == ["a", "b"]
    assert labels[1:3] == [[], ["a"]]
    assert list(labels) == labels.tolist()
    with pytest.raises(TypeError):
        hash(held)


def test_a_large_mesh_document_is_written_block_by_block_as_its_lists() -> None:
    rng = np.random.default_rng(7)
    vertices = rng.normal(size=(arrays.BLOCK_ROWS * 2 + 5, 2)) * 1e3
    triangles = rng.integers(0, len(vertices), size=(arrays.BLOCK_ROWS + 1, 3))
    letters = [[], ["r1"], ["r1", "r2"]]
    letter_of = rng.integers(0, 3, size=len(triangles))
    held = {
        "vertices": ArrayList(vertices),
        "triangles": ArrayList(triangles),
        "labels": TableList(letters, letter_of),
        "letters": letters,
    }
    simple = {
        "vertices": vertices.tolist(),
        "triangles": triangles.tolist(),
        "labels": [letters[i] for i in letter_of.tolist()],
        "letters": letters,
    }
    assert dumps(held) == _reference(simple)
    assert "".join(dump_pieces(held)) == _reference(simple)
