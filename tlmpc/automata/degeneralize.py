"""Degeneralization: a TGBA with k acceptance sets → a state-based Büchi automaton.

States are (q, level); level k means "every set was seen since the last visit", and those
states are accepting.  Leaving an accepting state restarts at level 0; an edge carrying
several of the awaited marks advances several levels at once (the Spot/SPIN skip).  Levels
are tracked only inside accepting SCCs (elsewhere no run can be accepting, so one copy of
each state suffices), and entering an accepting SCC may start at level 0 or at level k
(visiting an accepting state once more is harmless); both are built and the smaller kept.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Iterator, Sequence

from tlmpc.automata.model import Automaton, Edge
from tlmpc.automata.simplify import merge_parallel, sccs, trim


def _accepting_sccs(automaton: Automaton, component: list[int]) -> set[int]:
    seen: dict[int, set[int]] = {}
    for edge in automaton.edges:
        if component[edge.src] >= 0 and component[edge.src] == component[edge.dst]:
            seen.setdefault(component[edge.src], set()).update(edge.marks)
    everything = set(range(automaton.num_acc))
    return {c for c, marks in seen.items() if marks >= everything}


def _build(automaton: Automaton, enter_at_top: bool) -> Automaton:
    k = automaton.num_acc
    component = sccs(automaton.num_states, automaton.edges, automaton.initial)
    accepting_scc = _accepting_sccs(automaton, component)
    out: dict[int, list[Edge]] = {}
    for edge in automaton.edges:
        out.setdefault(edge.src, []).append(edge)

    def entry_level(state: int) -> int:
        if component[state] not in accepting_scc:
            return 0
        return k if enter_at_top else 0

    start = (automaton.initial, entry_level(automaton.initial))
    index = {start: 0}
    queue = [start]
    edges: list[tuple[int, int, Edge]] = []
    for state, level in queue:
        for edge in out.get(state, []):
            if component[edge.src] != component[edge.dst]:
                target = (edge.dst, entry_level(edge.dst))
            elif component[edge.src] not in accepting_scc:
                target = (edge.dst, 0)
            else:
                reached = 0 if level == k else level
                while reached < k and reached in edge.marks:
                    reached += 1
                target = (edge.dst, reached)
            if target not in index:
                index[target] = len(index)
                queue.append(target)
            edges.append((index[(state, level)], index[target], edge))
    accepting = {
        i for (state, level), i in index.items() if level == k and component[state] in accepting_scc
    }
    names = [
        f"{automaton.state_names[s] if s < len(automaton.state_names) else s} [{lvl}]"
        for (s, lvl) in index
    ]
    result = Automaton(
        aps=automaton.aps,
        num_states=len(index),
        initial=0,
        edges=tuple(
            merge_parallel(
                [
                    Edge(
                        src=s,
                        dst=d,
                        guard=e.guard,
                        marks=frozenset({0}) if s in accepting else frozenset(),
                    )
                    for s, d, e in edges
                ]
            )
        ),
        num_acc=1,
        state_names=tuple(names),
        formula=automaton.formula,
        state_based=True,
    )
    trimmed = trim(result)
    # Trimming drops marks on edges that lie on no cycle; keep the marks state-based.
    marked = {e.src for e in trimmed.edges if e.marks}
    return Automaton(
        aps=trimmed.aps,
        num_states=trimmed.num_states,
        initial=trimmed.initial,
        edges=tuple(
            Edge(
                src=e.src,
                dst=e.dst,
                guard=e.guard,
                marks=frozenset({0}) if e.src in marked else frozenset(),
            )
            for e in trimmed.edges
        ),
        num_acc=1,
        state_names=trimmed.state_names,
        formula=trimmed.formula,
        state_based=True,
    )


def degeneralize(automaton: Automaton) -> Automaton:
    """An equivalent state-based Büchi automaton (one acceptance set, marks on states)."""
    return dataclasses.replace(_degeneralize(automaton), letters=automaton.letters)


def _degeneralize(automaton: Automaton) -> Automaton:
    if automaton.num_acc == 0 and automaton.edges:
        # Every infinite run accepts: mark every state of the (already trimmed) automaton.
        return Automaton(
            aps=automaton.aps,
            num_states=automaton.num_states,
            initial=automaton.initial,
            edges=tuple(
                Edge(src=e.src, dst=e.dst, guard=e.guard, marks=frozenset({0}))
                for e in automaton.edges
            ),
            num_acc=1,
            state_names=automaton.state_names,
            formula=automaton.formula,
            state_based=True,
        )
    candidates = [_build(automaton, False), _build(automaton, True)]
    return min(candidates, key=lambda a: (a.num_states, len(a.edges)))


def acceptance_orders(count: int) -> Iterator[tuple[int, ...]]:
    """The orders in which a degeneralization can await ``count`` acceptance sets, one per
    cycle of visits up to where it starts and which way round it runs: set 0 first, the
    second set before the last (the reverse order visits the same sets along the same
    tour).  The identity comes first; ``(count - 1)! / 2`` orders for three sets or more."""
    if count < 3:
        yield tuple(range(count))
        return
    for rest in itertools.permutations(range(1, count)):
        if rest[0] < rest[-1]:
            yield (0, *rest)


def reorder_acceptance(automaton: Automaton, order: Sequence[int]) -> Automaton:
    """The same automaton with acceptance set ``order[i]`` renumbered ``i`` (the language is
    unchanged): :func:`degeneralize` then awaits the sets in ``order``, and a minimum-cost
    lasso of its product visits them in that order once a lap."""
    if sorted(order) != list(range(automaton.num_acc)):
        raise ValueError(f"not an order of {automaton.num_acc} acceptance sets: {order}")
    rank = {mark: index for index, mark in enumerate(order)}
    edges = tuple(
        dataclasses.replace(edge, marks=frozenset(rank[m] for m in edge.marks))
        for edge in automaton.edges
    )
    return dataclasses.replace(automaton, edges=edges)
