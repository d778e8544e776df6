"""Stage 8: the independent verifier of trajectories (continuous-time LTL semantics).

Imports nothing from the abstraction, automata, planning, control or simulation stages.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from tlmpc.verify.trace_input import TraceInput, from_csv, from_document
from tlmpc.verify.verdict import Counterexample, Verdict, verdict_to_json, verify_trace


def verify_document(
    document: Mapping[str, Any], *, boundary: str | None = None, file: str | None = None
) -> Verdict:
    """Verify a ``tlmpc.trace/1`` document (``boundary`` overrides its convention)."""
    return verify_trace(from_document(document, file=file, convention=boundary))


__all__ = [
    "Counterexample",
    "TraceInput",
    "Verdict",
    "from_csv",
    "from_document",
    "verdict_to_json",
    "verify_document",
    "verify_trace",
]
