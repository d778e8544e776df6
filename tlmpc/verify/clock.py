"""Times as the verifier decides and reports them: from the log's first sample.

A robot's log is stamped with its clock (a ROS header stamp: seconds since 1970, or since the
simulator started); a person reads "12.3 s into the log".  The verifier decides every time
bound on times counted from the first sample (:func:`since_first`): the stamps less the first
one, differences that are exact at any epoch, where a window end at 1.7e9 s would be rounded to
a quarter of a microsecond and onto an instant nearby.  Every time in a message is written
``t=12.3 s`` from the first sample, followed by ``(stamp 1432235512.3)`` when the log does not
start at 0, so the moment can still be found in the log itself.  The JSON documents keep the
absolute stamps (``time`` fields) and give the log's start as ``stats.start_time``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

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


def _written(relative: float, stamp: float, stamped: bool) -> str:
    """``t=REL s``, with ``(stamp STAMP)`` beside when ``stamped``."""
    if relative == 0.0:
        relative = 0.0  # no "-0"
    if not stamped:
        return f"t={seconds(relative)} s"
    text = f"{stamp:.3f}".rstrip("0").rstrip(".")  # to the millisecond, as bags are read
    return f"t={seconds(relative)} s (stamp {text})"


def at(time: float, start: float) -> str:
    """``t=REL s`` of the absolute ``time`` in a log whose first sample is at ``start``,
    with ``(stamp TIME)`` beside when the log does not start at 0."""
    return _written(time - start, time, start != 0.0)


def since_first(times: FloatArray) -> FloatArray:
    """A log's stamps ``times`` counted from the first of them: the times the verifier decides
    bounds on (each difference is exact when the log is shorter than its first stamp, as a
    log stamped from an epoch is)."""
    relative: FloatArray = np.asarray(times, dtype=np.float64) - float(times[0])
    return relative


@dataclass(frozen=True, slots=True)
class Clock:
    """How the verifier's times (seconds from the log's first sample, :func:`since_first`)
    map to the log's stamps and are written."""

    #: the stamp of the first sample: the verifier's time 0
    zero: float = 0.0
    #: the stamp messages count from: the log's start (before ``zero`` for a stretch of a
    #: longer log, as the live monitor checks)
    start: float = 0.0

    def stamp(self, time: float) -> float:
        """The log's stamp of the verifier's ``time``."""
        return self.zero + time

    def at(self, time: float) -> str:
        """``t=REL s`` of the verifier's ``time`` counted from the log's start, with
        ``(stamp TIME)`` beside when the log does not start at 0 (as :func:`at`)."""
        # from the first sample the time itself, not its stamp less the first one (rounded)
        relative = time if self.start == self.zero else time + (self.zero - self.start)
        return _written(relative, self.stamp(time), self.start != 0.0)


def elapsed(time: float, start: float) -> float:
    """Seconds from the log's start."""
    return time - start
