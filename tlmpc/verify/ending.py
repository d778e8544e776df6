"""How a trace ends, as the user declares it: ``--assume-stay`` and ``--loop-from T``."""

from __future__ import annotations

import dataclasses

import numpy as np

from tlmpc.base.errors import UsageError, error
from tlmpc.verify.trace_input import TraceInput


def declare_ending(
    trace: TraceInput, *, assume_stay: bool = False, loop_from: float | None = None
) -> TraceInput:
    """``trace`` read as staying at its last point, or repeating from ``loop_from`` seconds
    after its first sample on (times are counted from the log's start, as reported).

    Without either, the trace keeps the ending it declares itself (a log: ``open``).
    """
    if assume_stay and loop_from is not None:
        raise UsageError(
            error(
                "V022",
                "--assume-stay and --loop-from contradict each other",
                hint="a log either stays at its last point or repeats a part, not both",
                file=trace.source,
            )
        )
    if assume_stay:
        return dataclasses.replace(trace, ending="stay", loop_start=None)
    if loop_from is None:
        return trace
    times = trace.times - trace.times[0]
    if not np.isfinite(loop_from) or not 0.0 <= loop_from < times[-1]:
        raise UsageError(
            error(
                "V022",
                f"--loop-from {loop_from:g} is outside the log's time range "
                f"[0, {times[-1]:g}) (seconds from its first sample)",
                hint="give the time at which the repeating part of the log starts",
                file=trace.source,
            )
        )
    start = int(np.searchsorted(times, loop_from, side="left"))
    if len(times) - start < 2:
        raise UsageError(
            error(
                "V023",
                f"the loop from t={loop_from:g} has {len(times) - start} sample(s); "
                "a repeating part needs at least 2",
                hint="start the loop earlier",
                file=trace.source,
            )
        )
    return dataclasses.replace(trace, ending="loop", loop_start=start)
