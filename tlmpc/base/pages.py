"""Large arrays written whole at once, without numpy's request for transparent huge pages.

numpy asks the kernel (``madvise(MADV_HUGEPAGE)``) to back every array of 4 MiB or more with
huge pages.  Where the kernel's huge pages are in ``madvise`` mode with ``defrag`` also in
``madvise`` mode (a common default), every first touch of such an array may compact memory
to find a free 2 MiB page: an array of millions of nodes that a search fills with ``inf``
when it is allocated then costs several times its writing in system time (measured: eight
arrays of 8.4M entries, 1.36 CPU s with the request, 0.31 s without, on the project's
machine).  The planner's per-node search arrays are such arrays; they are allocated here
with the request turned off.  Only where the memory comes from changes, never a value.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator
from contextlib import contextmanager


def _switch() -> Callable[[bool], bool] | None:
    """numpy's switch of its huge-page request (it returns the previous setting)."""
    for module in ("numpy._core.multiarray", "numpy.core.multiarray"):  # numpy 2, numpy 1
        try:
            switch = getattr(importlib.import_module(module), "_set_madvise_hugepage", None)
        except ImportError:  # pragma: no cover - the other numpy's name
            continue
        if callable(switch):
            return switch  # type: ignore[no-any-return]
    return None  # pragma: no cover - every supported numpy has it


@contextmanager
def plain_pages() -> Iterator[None]:
    """Arrays allocated inside the block get no huge-page request (the previous setting is
    restored on leaving, also after an error)."""
    switch = _switch()
    if switch is None:  # pragma: no cover - see _switch
        yield
        return
    previous = switch(False)
    try:
        yield
    finally:
        switch(previous)
