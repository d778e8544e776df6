"""Times as the verifier reports them: from the log's start, the absolute stamp beside.

A robot's log is stamped with its clock (a ROS header stamp: seconds since 1970, or since the
simulator started); a person reads "12.3 s into the log".  Every time in a message is written
``t=12.3 s`` from the first sample, followed by ``(stamp 1432235512.3)`` when the log does not
start at 0, so the moment can still be found in the log itself.  The JSON documents keep the
absolute stamps (``time`` fields) and give the log's start as ``stats.start_time``.
"""

from __future__ import annotations

import math

#: Below this many seconds a time is written to four significant digits, from it on to the
#: tenth of a second (``t=43210.5 s``, not ``t=4.321e+04 s``), up to :data:`PLAIN_LIMIT`.
TENTHS_FROM = 1000.0
PLAIN_LIMIT = 1e9


def seconds(value: float) -> str:
    """A time or a duration in seconds as text (without the unit): four significant digits
    below :data:`TENTHS_FROM`, to the tenth of a second beyond, so that a moment hours into a
    log can be found in the log itself."""
    if math.isfinite(value) and TENTHS_FROM <= abs(value) < PLAIN_LIMIT:
        return f"{value:.1f}"
    return f"{value:.4g}"


def at(time: float, start: float) -> str:
    """``t=REL s`` of the absolute ``time`` in a log whose first sample is at ``start``,
    with ``(stamp TIME)`` beside when the log does not start at 0."""
    relative = time - start
    if relative == 0.0:
        relative = 0.0  # no "-0"
    if start == 0.0:
        return f"t={seconds(relative)} s"
    stamp = f"{time:.3f}".rstrip("0").rstrip(".")  # to the millisecond, as bags are read
    return f"t={seconds(relative)} s (stamp {stamp})"


def elapsed(time: float, start: float) -> float:
    """Seconds from the log's start."""
    return time - start
