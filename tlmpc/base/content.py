"""Equality of the stages' results on their content.

A stage's result is a frozen dataclass that holds numpy arrays (vertices, triangles, samples)
beside plain fields and a ``stats`` mapping that also reports how long the stage took.  The
equality a dataclass generates cannot compare arrays (``==`` on two arrays is an array), and
timings differ from one run to the next though the result is the same.  :class:`ContentEquality`
gives the dataclasses that inherit it (declared with ``eq=False``) the equality that means
"the same result": every field that takes part in comparisons, arrays by shape, dtype and
value (NaN equal to NaN), mappings key by key, leaving out of the ``stats`` mapping every key
that ends in ``seconds`` (the timing fields; elsewhere such a key, a region's name say, is
content).  Nothing here imports numpy: arrays are recognised by their attributes.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

#: Keys of a stats mapping that report time, not content.
TIMING_SUFFIX = "seconds"
#: The fields that hold such a mapping.
STATS_FIELDS = frozenset({"stats"})


def _is_array(value: object) -> bool:
    return hasattr(value, "__array__") and hasattr(value, "dtype") and hasattr(value, "shape")


def same_content(left: object, right: object, *, stats: bool = False) -> bool:
    """Whether two values hold the same content (see the module doc); with ``stats``, the
    mappings' timing keys are left out."""
    if _is_array(left) or _is_array(right):
        if not (_is_array(left) and _is_array(right)):
            return False
        return _same_array(left, right)
    if isinstance(left, Mapping) and isinstance(right, Mapping):
        keys = {k for k in left if not (stats and _is_timing(k))}
        if keys != {k for k in right if not (stats and _is_timing(k))}:
            return False
        return all(same_content(left[k], right[k], stats=stats) for k in keys)
    if isinstance(left, tuple | list) and isinstance(right, tuple | list):
        return (
            type(left) is type(right)
            and len(left) == len(right)
            and all(same_content(a, b, stats=stats) for a, b in zip(left, right, strict=True))
        )
    return bool(left == right)


def _is_timing(key: object) -> bool:
    return isinstance(key, str) and key.endswith(TIMING_SUFFIX)


def _same_array(left: Any, right: Any) -> bool:
    import numpy as np

    if left.shape != right.shape or left.dtype != right.dtype:
        return False
    inexact = np.issubdtype(left.dtype, np.inexact)
    return bool(np.array_equal(left, right, equal_nan=inexact))


def _hashable(value: object) -> object:
    """What of a field enters the hash: equal contents give equal hashes."""
    if _is_array(value):
        return (getattr(value, "shape", None), str(getattr(value, "dtype", "")))
    if isinstance(value, Mapping):
        return None
    return value


class ContentEquality:
    """Equality (and a hash that agrees with it) on content; see the module doc."""

    __slots__ = ()

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(
            same_content(
                getattr(self, field.name),
                getattr(other, field.name),
                stats=field.name in STATS_FIELDS,
            )
            for field in dataclasses.fields(self)  # type: ignore[arg-type]
            if field.compare
        )

    def __hash__(self) -> int:
        return hash(
            (
                type(self).__qualname__,
                *(
                    _hashable(getattr(self, field.name))
                    for field in dataclasses.fields(self)  # type: ignore[arg-type]
                    if field.compare
                ),
            )
        )
