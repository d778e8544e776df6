"""Work budgets: the optional reductions stop after a count of operations, never a time.

The translation's optional steps (the simulation reductions, WDBA minimization and its
equivalence check, the semantic rewriting and containment checks) may stop early and keep the
automaton reduced so far, which is always correct.  When to stop is decided by a count of
*work units* that those steps charge as they go (a unit is about one edge visited, or one
state expanded), never by a clock: the same formula gives the same automaton, hence the same
plan and the same bytes, on a fast machine, a slow one and a loaded one.

The count is per thread and only grows.  A budget of ``b`` units is the deadline
``spent() + b``; the steps compare :func:`spent` with it (:func:`charge` also raises
:class:`OutOfBudget` past it).  Units are charged only outside the translator's caches (sizes
of the automata at hand, not the work a cache hit saves), so the count does not depend on what
the process translated before.
"""

from __future__ import annotations

import threading


class OutOfBudget(Exception):
    """A reduction's work budget ran out (the caller keeps what it has)."""


class _Counter(threading.local):
    units = 0


_COUNTER = _Counter()


def spent() -> int:
    """The work units charged so far in this thread."""
    return _COUNTER.units


def charge(deadline: float, units: int = 1) -> None:
    """Count ``units`` of work; :class:`OutOfBudget` when the count passes ``deadline``."""
    _COUNTER.units += units
    if _COUNTER.units > deadline:
        raise OutOfBudget


def over(deadline: float, units: int = 0) -> bool:
    """Count ``units`` of work and tell whether the count is past ``deadline``."""
    _COUNTER.units += units
    return _COUNTER.units > deadline
