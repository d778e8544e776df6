"""What one compilation computes once and several of its stages reuse.

A run of the stages (:func:`tlmpc.pipeline.stages.run_stages`: a compile, or one stage run
from its artifacts) opens one :class:`Memo` and makes it the *current* memo while its stages
run (:func:`memo_scope`).  Code deep inside a stage asks :func:`recall` for a value derived
from an object it holds (the convex cells of a mesh, the regions' document of a mission's
polygons): the first ask in the run builds it, later asks get the same object.  When the run
ends, the memo goes, and with it every value and every object held for it; two runs never see
each other's values.  Outside any run nothing is remembered: each ask builds anew.

Why a context variable rather than a parameter: the askers sit several calls below the stage
functions (the planner's masks and searches, the cell fields of the control stage, three
artifact encoders), and the value is an optimisation that must not change a result, so the
signatures in between need not carry it.  The variable is per thread (and per asyncio task):
runs on other threads each have their own.
"""

from __future__ import annotations

import contextlib
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable, Iterator
from contextvars import ContextVar
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

T = TypeVar("T")


@dataclass(frozen=True, slots=True, eq=False)
class Slot(Generic[T]):
    """One kind of remembered value: its name and how many of them a memo keeps (the most
    recently asked for; older ones are built again when asked for again)."""

    name: str
    keep: int


class Memo:
    """The values one run of the stages remembers, per :class:`Slot`, by key.

    Each value is kept with the object it was derived from (``held``), so that an ``id`` in
    its key cannot be reused by another object while the value is kept.
    """

    def __init__(self) -> None:
        self._values: dict[Slot[Any], OrderedDict[Hashable, tuple[object, Any]]] = {}
        self._lock = threading.Lock()

    def recall(self, slot: Slot[T], key: Hashable, held: object, build: Callable[[], T]) -> T:
        """The value of ``slot`` under ``key``, built by ``build`` on the first ask."""
        with self._lock:
            kept = self._values.setdefault(slot, OrderedDict())
            found = kept.get(key)
            if found is not None:
                kept.move_to_end(key)
                value: T = found[1]
                return value
        value = build()
        with self._lock:
            kept[key] = (held, value)
            while len(kept) > slot.keep:
                kept.popitem(last=False)
        return value

    def size(self, slot: Slot[Any]) -> int:
        """How many values of ``slot`` are kept."""
        return len(self._values.get(slot, ()))


_CURRENT: ContextVar[Memo | None] = ContextVar("tlmpc_memo", default=None)


@contextlib.contextmanager
def memo_scope(memo: Memo | None = None) -> Iterator[Memo]:
    """Make ``memo`` (a new one when None) the current memo until the block ends."""
    current = Memo() if memo is None else memo
    token = _CURRENT.set(current)
    try:
        yield current
    finally:
        _CURRENT.reset(token)


def current_memo() -> Memo | None:
    """The memo of the run under way, or None outside any."""
    return _CURRENT.get()


def recall(slot: Slot[T], key: Hashable, held: object, build: Callable[[], T]) -> T:
    """:meth:`Memo.recall` on the current memo; outside a run, ``build()`` itself."""
    memo = _CURRENT.get()
    if memo is None:
        return build()
    return memo.recall(slot, key, held, build)
