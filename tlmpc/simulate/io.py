"""``trace.json`` (``tlmpc.trace/1``) read back into a :class:`Trace`."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from tlmpc.simulate.exact import Trace


def trace_from_json(document: Mapping[str, Any]) -> Trace:
    """The samples, plan steps and triangles of a trace written by ``trace_to_json``."""
    samples = np.asarray(document["points"], dtype=np.float64).reshape(-1, 3)
    times = np.ascontiguousarray(samples[:, 0])
    points = np.ascontiguousarray(samples[:, 1:])
    times.setflags(write=False)
    points.setflags(write=False)
    return Trace(
        times=times,
        points=points,
        steps=tuple(int(k) for k in document["steps"]),
        triangles=tuple(int(k) for k in document["triangles"]),
        loop_start=document["loop_start"],
        crossings=tuple(int(k) for k in document.get("crossings", ())),
    )
