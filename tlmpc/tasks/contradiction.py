"""Contradictory tasks: a task no behaviour at all can satisfy, located at its phrases.

A task is a contradiction when its Büchi automaton accepts no word over *all* letters (every
set of regions, overlapping or not): then no workspace, map or robot can satisfy it, and the
mission is wrong whatever its geometry.  The check translates the conjunction of the task's
parts (each phrase, the ``ltl:`` formula) and looks for a reachable cycle through every
acceptance set.  When the task is empty it shrinks the parts to a minimal contradictory core
(dropping each part whose removal keeps the conjunction empty) and reports it at the first
part of the core (T011 for phrases, L020 when the ``ltl:`` formula alone is unsatisfiable).

Pure Python on tlmpc's own automata: fast enough for ``tlmpc check`` in a pre-commit hook.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from tlmpc.automata.translate import translate
from tlmpc.base.errors import Diagnostic, error
from tlmpc.base.graphs import csr, strong_components
from tlmpc.ltl.ast import And, Formula, Or, Prop, bounded_operators, conjoin, is_temporal
from tlmpc.ltl.printer import to_text
from tlmpc.ltl.transform import substitute

#: Conjuncts are checked in groups that share regions (groups over disjoint regions are
#: independent, since every letter is allowed); a group with more temporal operators than this
#: is not checked (the translation is exponential in the worst case and the hook must stay
#: fast); ``tlmpc compile`` still reports an impossible task as "no plan".
MAX_TEMPORAL_OPERATORS = 8


@dataclass(frozen=True, slots=True, kw_only=True)
class TaskPart:
    """One conjunct of a task as written: a phrase or the ``ltl:`` formula, with its place."""

    formula: Formula
    text: str
    kind: str  # "phrase" or "ltl"
    line: int | None = None
    col: int | None = None


def is_satisfiable(formula: Formula) -> bool:
    """Whether some infinite word over all letters satisfies ``formula`` (LTL without X)."""
    # the translation's edges carry consistent cubes only (a & !a is never emitted), so every
    # edge is enabled by some letter and emptiness is a graph question
    automaton = translate(formula, simplify=False)
    successors: list[list[int]] = [[] for _ in range(automaton.num_states)]
    for edge in automaton.edges:
        successors[edge.src].append(edge.dst)
    component = strong_components(*csr(successors), [automaton.initial])
    # the marks on the edges inside each reachable component (a component with no inner
    # edge is on no cycle and gets no entry)
    inner: dict[int, set[int]] = {}
    for edge in automaton.edges:
        if component[edge.src] >= 0 and component[edge.src] == component[edge.dst]:
            inner.setdefault(component[edge.src], set()).update(edge.marks)
    wanted = frozenset(range(automaton.num_acc))
    return any(wanted <= marks for marks in inner.values())


def _temporal_size(formula: Formula) -> int:
    """How many temporal operators ``formula`` has: the unit of the check's budget
    (``->`` and ``<->`` are connectives, as ``&`` and ``|`` are)."""
    return sum(1 for node in formula.walk() if is_temporal(node))


def _conjuncts(formula: Formula) -> list[Formula]:
    if isinstance(formula, And):
        return [c for arg in formula.args for c in _conjuncts(arg)]
    return [formula]


def _independent_groups(formulas: Sequence[Formula]) -> list[list[Formula]]:
    """The conjuncts of ``formulas`` grouped by shared propositions (connected components)."""
    conjuncts = [c for f in formulas for c in _conjuncts(f)]
    groups: list[tuple[set[str], list[Formula]]] = []
    for conjunct in conjuncts:
        props = set(conjunct.props())
        touching = [g for g in groups if g[0] & props]
        merged_props = props.union(*(g[0] for g in touching))
        merged = [f for g in touching for f in g[1]] + [conjunct]
        groups = [g for g in groups if not g[0] & props] + [(merged_props, merged)]
    return [members for _, members in groups]


def contradictory(formulas: Sequence[Formula]) -> bool:
    """Whether the conjunction of ``formulas`` is certainly unsatisfiable.

    False also when a group of dependent conjuncts is too large to check, or has a time bound.
    """
    for group in _independent_groups(formulas):
        if sum(_temporal_size(f) for f in group) > MAX_TEMPORAL_OPERATORS:
            continue
        if any(bounded_operators(f) for f in group):
            continue  # the automaton check does not take time bounds
        if not is_satisfiable(conjoin(group)):
            return True
    return False


def find_contradiction(
    parts: Sequence[TaskPart],
    *,
    groups: Mapping[str, Sequence[str]] | None = None,
    file: str | None = None,
) -> Diagnostic | None:
    """The diagnostic of a contradictory task (None when some behaviour satisfies it)."""
    if not parts:
        return None
    expand: dict[str, Formula] = {
        g: Or(tuple(Prop(m) for m in members)) if len(members) > 1 else Prop(members[0])
        for g, members in (groups or {}).items()
        if members
    }
    formulas = [substitute(p.formula, expand) for p in parts]
    if not contradictory(formulas):
        return None
    core = list(range(len(parts)))
    for candidate in range(len(parts)):
        rest = [i for i in core if i != candidate]
        if rest and contradictory([formulas[i] for i in rest]):
            core = rest
    first = parts[core[0]]
    others = [parts[i] for i in core[1:]]
    if not others:
        what = "task phrase" if first.kind == "phrase" else "`ltl:` formula"
        message = f"the {what} {first.text!r} is a contradiction: nothing can satisfy it"
        hint = f"it means {to_text(formulas[core[0]])}, which no behaviour satisfies"
    else:
        message = f"the task is a contradiction: {first.text!r} cannot hold together with " + (
            ", ".join(_describe(p) for p in others)
        )
        hint = (
            "together they mean "
            + to_text(conjoin([formulas[i] for i in core]))
            + (", which no behaviour satisfies; drop or change one of them")
        )
    code = "L020" if first.kind == "ltl" and not others else "T011"
    return error(code, message, hint=hint, file=file, line=first.line, col=first.col)


def _describe(part: TaskPart) -> str:
    where = f" (line {part.line})" if part.line is not None else ""
    label = "the `ltl:` formula " if part.kind == "ltl" else ""
    return f"{label}{part.text!r}{where}"
