"""Language-containment simplification of a formula (Spot's ``tl_simplifier`` containment
checks, the rules of its "High" level), decided with tlmpc's own translator.

``L(a) ⊆ L(b)`` iff the automaton of ``a & !b`` is empty, and a trimmed automaton is empty iff
it has no edges.  Bottom-up, in every conjunction a conjunct implied by the others is dropped
(``a & b = a`` when ``a ⊆ b``), in every disjunction a disjunct implied by the others is dropped,
and a node equivalent to ``false`` / ``true`` becomes that constant.  Only small nodes over few
propositions are checked, within a work budget (:mod:`tlmpc.automata.work`: the emptiness checks
charge it); past it the formula is left as it is.
"""

from __future__ import annotations

from collections.abc import Callable

from tlmpc.automata import work
from tlmpc.ltl.ast import FALSE, TRUE, And, Formula, Not, Or, conjoin, disjoin

#: Nodes with more operands, or formulas over more propositions, are not checked.
MAX_OPERANDS = 4
MAX_APS = 6


def simplify_by_containment(
    formula: Formula, empty: Callable[[Formula], bool], deadline: float
) -> Formula:
    """``formula`` with operands implied by their siblings removed (same language)."""
    if len(formula.props()) > MAX_APS:
        return formula
    return _walk(formula, empty, deadline)


def _walk(formula: Formula, empty: Callable[[Formula], bool], deadline: float) -> Formula:
    if not isinstance(formula, And | Or) or work.over(deadline):
        return formula
    args = [_walk(a, empty, deadline) for a in formula.args]
    if len(args) > MAX_OPERANDS:
        return conjoin(args) if isinstance(formula, And) else disjoin(args)
    conjunction = isinstance(formula, And)
    kept = list(args)
    index = 0
    while index < len(kept) and len(kept) > 1:
        if work.over(deadline):
            break
        candidate = kept[index]
        others = kept[:index] + kept[index + 1 :]
        if conjunction:
            # others ⊆ candidate: the candidate adds nothing.
            redundant = empty(And((conjoin(others), Not(candidate))))
        else:
            # candidate ⊆ others: the candidate adds nothing.
            redundant = empty(And((candidate, Not(disjoin(others)))))
        if redundant:
            kept.pop(index)
        else:
            index += 1
    result = conjoin(kept) if conjunction else disjoin(kept)
    if not work.over(deadline) and empty(result if conjunction else Not(result)):
        return FALSE if conjunction else TRUE
    return result
