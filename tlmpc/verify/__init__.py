"""Stage 8: the independent verifier of trajectories (continuous-time LTL semantics).

Imports nothing from the abstraction, automata, planning, control or simulation stages.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from tlmpc.verify.ending import declare_ending
from tlmpc.verify.model import ConjunctReport, Counterexample, Verdict, Violation
from tlmpc.verify.trace_input import LogOptions, TraceInput, from_csv, from_document, read_trace
from tlmpc.verify.verdict import verdict_to_json, verify_trace


def verify_document(
    document: Mapping[str, Any],
    *,
    boundary: str | None = None,
    file: str | None = None,
    assume_stay: bool = False,
    loop_from: float | None = None,
) -> Verdict:
    """Verify a ``tlmpc.trace/1`` document (``boundary`` overrides its convention)."""
    trace = from_document(document, file=file, convention=boundary)
    return verify_trace(declare_ending(trace, assume_stay=assume_stay, loop_from=loop_from))


__all__ = [
    "ConjunctReport",
    "Counterexample",
    "LogOptions",
    "TraceInput",
    "Verdict",
    "Violation",
    "declare_ending",
    "from_csv",
    "from_document",
    "read_trace",
    "verdict_to_json",
    "verify_document",
    "verify_trace",
]
