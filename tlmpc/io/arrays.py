"""Large lists of an artifact held as numpy arrays until they are written.

A mesh of a million triangles is three lists of a million small lists in ``abstraction.json``:
as Python objects they take about half a gigabyte, kept from the abstraction stage until the
artifacts are written.  The stages put stand-ins in their documents instead: a
:class:`ArrayList` (the nested list ``array.tolist()``) or a :class:`TableList` (the list
``[table[i] for i in index]``), which hold the arrays only.  The writer encodes them piece by
piece, a block of rows at a time, into exactly the JSON text the plain list gives (the
encoder formats each Python number from ``tolist`` the same way, so the bytes are those of
the list encoded whole); :func:`plain` gives the plain document for everything else
(indented small documents, the public API, schema checks).

Both stand-ins read like the list they stand for (``len``, indexing, iteration, ``==`` with
a list) and ``numpy.asarray`` of an :class:`ArrayList` is its array.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator, Sequence
from itertools import chain
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # numpy is imported where arrays are encoded (``tlmpc check`` has none)
    import numpy as np
    import numpy.typing as npt

#: Rows encoded at a time: the text of one block (a few MB) is what the writer holds beyond
#: the arrays themselves.
BLOCK_ROWS = 1 << 16


class ArrayList:
    """The nested list ``array.tolist()``, held as the (read-only) array."""

    __slots__ = ("array",)
    __hash__ = None  # type: ignore[assignment]  # equal to a list, which has none

    def __init__(self, array: npt.NDArray[Any]) -> None:
        self.array = array

    @property
    def dtype(self) -> np.dtype[Any]:
        """The array's dtype."""
        return self.array.dtype

    @property
    def shape(self) -> tuple[int, ...]:
        """The array's shape."""
        return tuple(self.array.shape)

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> npt.NDArray[Any]:
        return self.array if dtype is None else self.array.astype(dtype, copy=False)

    def __len__(self) -> int:
        return len(self.array)

    def __getitem__(self, index: int | slice) -> Any:
        return self.array[index].tolist()

    def __iter__(self) -> Iterator[Any]:
        for start in range(0, len(self.array), BLOCK_ROWS):
            yield from self.array[start : start + BLOCK_ROWS].tolist()

    def __eq__(self, other: object) -> bool:
        if isinstance(other, ArrayList):
            return self.tolist() == other.tolist()
        if isinstance(other, list):
            return self.tolist() == other
        return NotImplemented

    def tolist(self) -> list[Any]:
        """The plain nested list."""
        plain: list[Any] = self.array.tolist()
        return plain


class TableList:
    """The list ``[table[i] for i in index]``: a long list of a few distinct values (each
    triangle's label set), held as the values and an index array."""

    __slots__ = ("index", "table")
    __hash__ = None  # type: ignore[assignment]

    def __init__(self, table: Sequence[Any], index: npt.NDArray[np.integer[Any]]) -> None:
        self.table = list(table)
        self.index = index

    def __len__(self) -> int:
        return len(self.index)

    def __getitem__(self, position: int | slice) -> Any:
        if isinstance(position, slice):
            return [self.table[i] for i in self.index[position].tolist()]
        return self.table[int(self.index[position])]

    def __iter__(self) -> Iterator[Any]:
        for start in range(0, len(self.index), BLOCK_ROWS):
            yield from map(self.table.__getitem__, self.index[start : start + BLOCK_ROWS].tolist())

    def __eq__(self, other: object) -> bool:
        if isinstance(other, TableList | list):
            return self.tolist() == list(other)
        return NotImplemented

    def tolist(self) -> list[Any]:
        """The plain list (its items are the table's own objects, as the list would hold)."""
        return list(map(self.table.__getitem__, self.index.tolist()))


Standin = ArrayList | TableList


def encoded_pieces(value: Standin, encoder: json.JSONEncoder) -> Iterator[str]:
    """The pieces of ``encoder.encode(value.tolist())``, a block of rows at a time.

    ``encoder`` must write compactly (``separators=(",", ":")``): the pieces are joined by
    ``,``.  What the encoder would refuse (a non-finite float: ValueError) is refused here,
    before the first piece is made, so that a writer never holds half a text it must drop.
    """
    import numpy as np

    if isinstance(value, TableList):
        texts = np.array(_item_texts(value.table, encoder), dtype=object)
        return _joined(len(value.index), lambda a, b: ",".join(texts[value.index[a:b]].tolist()))
    array = value.array
    if array.dtype.kind == "f" and not np.isfinite(array).all():
        raise ValueError("Out of range float values are not JSON compliant")
    return _joined(len(array), _rows_text(array, encoder))


#: How the encoder writes a Python number of each dtype kind: ``int.__repr__`` (what ``%d``
#: gives for an int) and ``float.__repr__`` (``%r`` of a float; the finite ones only, checked
#: before).  Booleans, strings and objects are left to the encoder.
_NUMBER_FORMATS = {"i": "%d", "u": "%d", "f": "%r"}


def _rows_text(array: npt.NDArray[Any], encoder: json.JSONEncoder) -> Callable[[int, int], str]:
    """The text of rows ``a:b`` of ``array`` as the compact encoder writes their list,
    without the brackets around it.

    A number array of one or two dimensions is formatted with one ``%`` per block, from a
    template of the rows' shape and the block's numbers as a flat ``tolist``: the same
    ``repr`` of each number the encoder takes, without a Python list per row (three times
    faster on a mesh's million triangles).
    """
    spec = _NUMBER_FORMATS.get(array.dtype.kind)
    if spec is None or array.ndim not in (1, 2):
        return lambda a, b: encoder.encode(array[a:b].tolist())[1:-1]
    row = spec if array.ndim == 1 else "[" + ",".join([spec] * array.shape[1]) + "]"

    def block(a: int, b: int) -> str:
        rows = array[a:b]
        return ",".join([row] * len(rows)) % tuple(rows.ravel().tolist())

    return block


def _joined(count: int, block: Callable[[int, int], str]) -> Iterator[str]:
    """``[`` + the texts of the blocks of ``count`` rows, joined by ``,`` + ``]``."""
    yield "["
    for start in range(0, count, BLOCK_ROWS):
        if start:
            yield ","
        yield block(start, start + BLOCK_ROWS)
    yield "]"


def _item_texts(items: list[Any], encoder: json.JSONEncoder) -> list[str]:
    """:func:`_item_text` of each item; when every item is a list of strings (the letters of
    a map of a hundred thousand rooms), with the types checked once for all of them."""
    quote = json.encoder.encode_basestring_ascii if encoder.ensure_ascii else None
    if (
        quote is not None
        and set(map(type, items)) <= {list}
        and set(map(type, chain.from_iterable(items))) <= {str}
    ):
        return ["[" + ",".join(map(quote, item)) + "]" for item in items]
    return [_item_text(item, encoder) for item in items]


def _item_text(item: Any, encoder: json.JSONEncoder) -> str:
    """``encoder.encode(item)``; a list of strings (a label set) joined from the encoder's
    own string encoding, a tenth of the time for the many letters of a large map."""
    if type(item) is list and all(type(name) is str for name in item):
        quote = json.encoder.encode_basestring_ascii if encoder.ensure_ascii else None
        if quote is not None:
            return "[" + ",".join(map(quote, item)) + "]"
    return encoder.encode(item)


def has_standins(document: Any) -> bool:
    """Whether ``document`` holds a stand-in in a top-level value (where stages put them)."""
    if type(document) is not dict:
        return False
    return any(isinstance(value, ArrayList | TableList) for value in document.values())


def plain(document: Any) -> Any:
    """``document`` with its stand-ins (top-level values, where stages put them) replaced by
    their plain lists; the document itself when it holds none."""
    if not has_standins(document):
        return document
    return {
        key: value.tolist() if isinstance(value, ArrayList | TableList) else value
        for key, value in document.items()
    }
