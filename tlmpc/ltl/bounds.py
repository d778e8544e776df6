"""Refusing time bounds where they cannot be honoured: the automaton translation and the
planner work on untimed LTL, so they refuse ``F[a,b]``, ``G[a,b]`` and ``U[a,b]`` (L045) at
the operator's position instead of silently dropping the bound.  ``tlmpc verify`` decides
time bounds exactly on a trajectory or a log."""

from __future__ import annotations

from tlmpc.base.errors import InvalidInputError, error
from tlmpc.ltl.ast import Formula, bounded_operators
from tlmpc.ltl.printer import to_text

#: At most this many bounded operators are named in one refusal.
MAX_NAMED = 3


def refuse_bounds(formula: Formula, *, file: str | None = None, purpose: str) -> None:
    """Raise L045 for each time-bounded operator of ``formula`` (none: return).

    ``purpose`` says what cannot take the bound (``"planning"``, ``"the automaton"``).
    """
    found = bounded_operators(formula)
    if not found:
        return
    diagnostics = []
    for node in found[:MAX_NAMED]:
        span = node.span
        diagnostics.append(
            error(
                "L045",
                f"{purpose} cannot take the time bound of `{to_text(node)}`",
                hint="tlmpc verify checks time bounds exactly on a trajectory or a log; to "
                "plan, state the task without the bound (F x instead of F[0,30] x) and check "
                "the compiled trace with `tlmpc verify --mission`",
                file=file,
                line=span.line if span is not None else None,
                col=span.col if span is not None else None,
            )
        )
    raise InvalidInputError(diagnostics)
