"""LTL (without X) → transition-based generalized Büchi automaton, Couvreur/Spot style.

States are conjunctions of NNF formulas (hash-consed tuples, implied conjuncts dropped).  The
one-step expansion of a state gives its edges: the letter constraint becomes the guard, the
next-obligations the target, and an edge belongs to acceptance set ``Acc[e]`` of eventuality
``e`` iff it does not postpone ``e``.  Then: dominated edges are removed, the automaton is
trimmed to the states that can reach an accepting cycle, marks on edges that lie on no cycle
are dropped, and states with the same outgoing behaviour are merged.  See docs/automata.md.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

from tlmpc.automata.model import Automaton, Edge
from tlmpc.automata.simplify import postprocess
from tlmpc.automata.terms import (
    FALSE,
    T,
    eventualities,
    expand,
    from_ast,
    simplify_state,
    to_text,
)
from tlmpc.ltl.ast import Formula, Not, Prop, conjoin
from tlmpc.ltl.printer import to_text as formula_text

State = frozenset[T]
Cube = tuple[frozenset[str], frozenset[str]]


def cube_formula(pos: Iterable[str], neg: Iterable[str]) -> Formula:
    """The conjunction of literals of a cube (``true`` for the empty cube)."""
    literals: list[Formula] = [Prop(p) for p in sorted(pos)]
    literals += [Not(Prop(n)) for n in sorted(neg)]
    return conjoin(literals)


def _dominated(
    terms: list[tuple[Cube, State, frozenset[int]]],
) -> list[tuple[Cube, State, frozenset[int]]]:
    """Drop every term that another term dominates.

    Term A dominates B when A is enabled whenever B is (weaker cube), leaves a weaker
    obligation (a subset of B's conjuncts) and carries at least B's marks: any accepting run
    through B can go through A instead.  Among distinct terms the relation is a partial order,
    so the undominated terms remain.
    """
    unique = list(dict.fromkeys(terms))
    kept = []
    # Distinct terms cannot dominate each other both ways, so "any other term" is safe.
    for i, (cube, target, marks) in enumerate(unique):
        pos, neg = cube
        for j, (other_cube, other_target, other_marks) in enumerate(unique):
            if (
                j != i
                and other_target <= target
                and other_cube[0] <= pos
                and other_cube[1] <= neg
                and other_marks >= marks
            ):
                break
        else:
            kept.append((cube, target, marks))
    return kept


def _letter_ok(cube: Cube, letters: Sequence[frozenset[str]] | None) -> bool:
    if letters is None:
        return True
    pos, neg = cube
    return any(pos <= letter and not (neg & letter) for letter in letters)


def translate(
    formula: Formula,
    *,
    letters: Sequence[Sequence[str]] | None = None,
    simplify: bool = True,
) -> Automaton:
    """Translate ``formula`` (no X) into a TGBA.

    Args:
        formula: the LTL formula.
        letters: when given, the only label sets that can occur (each the set of propositions
            true at once; all others false).  Edges no letter enables are dropped and states are
            merged with respect to these letters only.
        simplify: run the post-processing (trim, SCC pruning, merging).
    """
    root = from_ast(formula)
    aps = tuple(sorted(formula.props()))
    letter_sets = (
        None
        if letters is None
        else list(dict.fromkeys(frozenset(x for x in letter if x in aps) for letter in letters))
    )
    events = eventualities(root)
    event_index = {e: i for i, e in enumerate(events)}
    initial = simplify_state(frozenset([root])) if root != FALSE else None
    states: dict[State, int] = {}
    names: list[str] = []
    raw_edges: list[tuple[int, int, Cube, frozenset[int]]] = []
    if initial is not None:
        states[initial] = 0
        names.append(_state_name(initial))
        queue = [initial]
        while queue:
            state = queue.pop()
            source = states[state]
            terms: list[tuple[Cube, State, frozenset[int]]] = []
            for pos, neg, nxt, promises in _state_terms(state):
                target = simplify_state(nxt)
                if target is None or not _letter_ok((pos, neg), letter_sets):
                    continue
                marks = frozenset(i for e, i in event_index.items() if e not in promises)
                terms.append(((pos, neg), target, marks))
            for cube, target, marks in _dominated(terms):
                if target not in states:
                    states[target] = len(states)
                    names.append(_state_name(target))
                    queue.append(target)
                raw_edges.append((source, states[target], cube, marks))
    edges = tuple(
        Edge(src=s, dst=d, guard=cube_formula(*cube), marks=marks)
        for s, d, cube, marks in raw_edges
    )
    automaton = Automaton(
        aps=aps,
        num_states=max(len(states), 1),
        initial=0,
        edges=edges,
        num_acc=len(events),
        state_names=tuple(names) if names else ("false",),
        formula=formula_text(formula),
    )
    if simplify:
        automaton = postprocess(automaton, letter_sets)
    return automaton


def _state_terms(
    state: State,
) -> list[tuple[frozenset[str], frozenset[str], frozenset[T], frozenset[T]]]:
    terms: list[Any] = [(frozenset(), frozenset(), frozenset(), frozenset())]
    for part in sorted(state, key=repr):
        combined = []
        for pos, neg, nxt, prom in terms:
            for p2, n2, x2, pr2 in expand(part):
                p = pos | p2
                n = neg | n2
                if p & n:
                    continue
                combined.append((p, n, nxt | x2, prom | pr2))
        terms = combined
        if not terms:
            break
    return terms


def _state_name(state: State) -> str:
    if not state:
        return "true"
    return " & ".join(to_text(f) for f in sorted(state, key=repr))
