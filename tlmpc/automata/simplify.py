"""Post-processing of a TGBA: merge parallel edges, trim, SCC pruning, state merging."""

from __future__ import annotations

import dataclasses
import functools
from collections import defaultdict
from collections.abc import Callable, Sequence

from tlmpc.automata import simulation, wdba, work
from tlmpc.automata.guards import holds
from tlmpc.automata.model import Automaton, Edge
from tlmpc.base.graphs import csr, strong_components
from tlmpc.ltl.ast import TRUE, And, Formula, Not, Or, Prop, conjoin, disjoin

#: Guards with more cubes than this are left unabsorbed (the check is quadratic).
MAX_ABSORB = 256


def merge_parallel(edges: Sequence[Edge]) -> list[Edge]:
    """One edge per (source, target, marks): the disjunction of the guards."""
    grouped: dict[tuple[int, int, frozenset[int]], list[Formula]] = defaultdict(list)
    for edge in edges:
        grouped[(edge.src, edge.dst, edge.marks)].append(edge.guard)
    merged = []
    for (src, dst, marks), guards in grouped.items():
        unique = _absorb(list(dict.fromkeys(guards)))
        guard = TRUE if TRUE in unique else disjoin(unique)
        merged.append(Edge(src=src, dst=dst, guard=guard, marks=marks))
    return merged


def merge_parallel_automaton(automaton: Automaton) -> Automaton:
    """The automaton with :func:`merge_parallel` applied to its edges."""
    return Automaton(
        aps=automaton.aps,
        num_states=automaton.num_states,
        initial=automaton.initial,
        edges=tuple(merge_parallel(automaton.edges)),
        num_acc=automaton.num_acc,
        state_names=automaton.state_names,
        formula=automaton.formula,
        state_based=automaton.state_based,
    )


def _literals(guard: Formula) -> frozenset[Formula] | None:
    """The literals of a cube guard (``true`` = no literals); None for other guards."""
    if guard == TRUE:
        return frozenset()
    if isinstance(guard, Prop) or (isinstance(guard, Not) and isinstance(guard.arg, Prop)):
        return frozenset([guard])
    if isinstance(guard, And) and all(_literals(a) is not None for a in guard.args):
        return frozenset(guard.args)
    return None


def _absorb(guards: list[Formula]) -> list[Formula]:
    """Drop disjuncts implied by another disjunct (``a | a & b`` = ``a``)."""
    if len(guards) == 1 and not isinstance(guards[0], Or):
        return guards
    flat = [g for guard in guards for g in (guard.args if isinstance(guard, Or) else (guard,))]
    if len(flat) > MAX_ABSORB:
        return flat  # quadratic; a longer guard is still the same guard
    cubes = [_literals(g) for g in flat]
    kept = []
    for i, guard in enumerate(flat):
        mine = cubes[i]
        absorbed = mine is not None and any(
            other is not None and other <= mine and (other != mine or j < i)
            for j, other in enumerate(cubes)
            if j != i
        )
        if not absorbed:
            kept.append(guard)
    return kept


def sccs(num_states: int, edges: Sequence[Edge], initial: int) -> list[int]:
    """SCC id of every state reachable from ``initial`` (-1 for unreachable), in Tarjan's
    order (see :func:`tlmpc.base.graphs.strong_components`)."""
    succ: list[list[int]] = [[] for _ in range(num_states)]
    for edge in edges:
        succ[edge.src].append(edge.dst)
    return strong_components(*csr(succ), [initial])


def trim(automaton: Automaton, *, keep_transient_marks: bool = False) -> Automaton:
    """Keep the states that can reach an accepting cycle; drop marks on acyclic edges
    (unless ``keep_transient_marks``)."""
    edges = automaton.edges
    component = sccs(automaton.num_states, edges, automaton.initial)
    all_marks = frozenset(range(automaton.num_acc))
    internal: dict[int, set[int]] = defaultdict(set)
    cyclic: set[int] = set()
    for edge in edges:
        if component[edge.src] >= 0 and component[edge.src] == component[edge.dst]:
            cyclic.add(component[edge.src])
            internal[component[edge.src]].update(edge.marks)
    accepting = {c for c in cyclic if internal[c] >= all_marks}
    # States that can reach an accepting SCC (backwards search).
    preds: dict[int, list[int]] = defaultdict(list)
    for edge in edges:
        preds[edge.dst].append(edge.src)
    useful = {s for s in range(automaton.num_states) if component[s] in accepting}
    frontier = list(useful)
    while frontier:
        state = frontier.pop()
        for source in preds[state]:
            if source not in useful and component[source] >= 0:
                useful.add(source)
                frontier.append(source)
    kept = [
        Edge(
            src=e.src,
            dst=e.dst,
            guard=e.guard,
            marks=e.marks
            if keep_transient_marks or component[e.src] == component[e.dst]
            else frozenset(),
        )
        for e in edges
        if e.src in useful and e.dst in useful
    ]
    return _renumber(automaton, kept, useful)


def _renumber(automaton: Automaton, edges: Sequence[Edge], keep: set[int]) -> Automaton:
    """Keep ``keep`` states, numbered in breadth-first order from the initial state."""
    if automaton.initial not in keep:
        return Automaton(
            aps=automaton.aps,
            num_states=1,
            initial=0,
            edges=(),
            num_acc=0,
            state_names=("false",),
            formula=automaton.formula,
            state_based=automaton.state_based,
        )
    out: dict[int, list[Edge]] = defaultdict(list)
    for edge in edges:
        out[edge.src].append(edge)
    order = {automaton.initial: 0}
    queue = [automaton.initial]
    for state in queue:
        for edge in sorted(out[state], key=lambda e: (e.dst, sorted(e.marks))):
            if edge.dst not in order:
                order[edge.dst] = len(order)
                queue.append(edge.dst)
    renumbered = sorted(
        (
            Edge(src=order[e.src], dst=order[e.dst], guard=e.guard, marks=e.marks)
            for e in edges
            if e.src in order and e.dst in order
        ),
        key=lambda e: (e.src, e.dst, sorted(e.marks)),
    )
    # Parallel edges with equal marks keep a deterministic order (set iteration order of
    # names depends on the hash seed): sort each run of ties by guard text.
    start = 0
    for end in range(1, len(renumbered) + 1):
        if end == len(renumbered) or (
            (renumbered[end].src, renumbered[end].dst, renumbered[end].marks)
            != (renumbered[start].src, renumbered[start].dst, renumbered[start].marks)
        ):
            if end - start > 1:
                renumbered[start:end] = sorted(renumbered[start:end], key=lambda e: str(e.guard))
            start = end
    names = automaton.state_names
    new_names = [""] * len(order)
    for old, new in order.items():
        new_names[new] = names[old] if old < len(names) else str(old)
    return Automaton(
        aps=automaton.aps,
        num_states=len(order),
        initial=0,
        edges=tuple(renumbered),
        num_acc=automaton.num_acc,
        state_names=tuple(new_names),
        formula=automaton.formula,
        state_based=automaton.state_based,
    )


def _reduce_marks(automaton: Automaton, *, keep_transient_marks: bool = False) -> Automaton:
    """Keep marks only inside accepting SCCs, then drop or merge redundant acceptance sets.

    A run is accepted iff it ends in an accepting SCC and sees every set there, so marks
    elsewhere are useless.  A set carried by every edge of every accepting SCC is then
    implied by staying in one; it is dropped, except that one set must survive whenever some
    cycle lies outside the accepting SCCs (with no sets left every cycle would accept).
    Sets carried by the same edges are merged.  With ``keep_transient_marks``, edges
    between SCCs that enter an accepting SCC keep their marks (renumbered like the others;
    a run takes them once, so any marks will do there, and these are the construction's).
    """
    k = automaton.num_acc
    if k == 0:
        return automaton
    component = sccs(automaton.num_states, automaton.edges, automaton.initial)
    everything = frozenset(range(k))
    internal: dict[int, set[int]] = defaultdict(set)
    cyclic: set[int] = set()
    for e in automaton.edges:
        if component[e.src] == component[e.dst]:
            cyclic.add(component[e.src])
            internal[component[e.src]].update(e.marks)
    accepting = {c for c in cyclic if internal[c] >= everything}
    stripped = [
        e.marks
        if (component[e.src] == component[e.dst] and component[e.src] in accepting)
        or (keep_transient_marks and component[e.dst] in accepting)
        else frozenset()
        for e in automaton.edges
    ]
    inside = [
        i
        for i, e in enumerate(automaton.edges)
        if component[e.src] in accepting and component[e.src] == component[e.dst]
    ]
    keep: list[int] = []
    seen: set[frozenset[int]] = set()
    for mark in range(k):
        carriers = frozenset(i for i in inside if mark in stripped[i])
        if len(carriers) == len(inside) or carriers in seen:
            continue
        seen.add(carriers)
        keep.append(mark)
    keep = _drop_implied_sets(
        keep, [component[automaton.edges[i].src] for i in inside], [stripped[i] for i in inside]
    )
    if not keep and (cyclic - accepting):
        keep = [0]
    new_index = {old: new for new, old in enumerate(keep)}
    edges = tuple(
        Edge(
            src=e.src,
            dst=e.dst,
            guard=e.guard,
            marks=frozenset(new_index[m] for m in marks if m in new_index),
        )
        for e, marks in zip(automaton.edges, stripped, strict=True)
    )
    if edges == automaton.edges and len(keep) == k:
        return automaton
    return Automaton(
        aps=automaton.aps,
        num_states=automaton.num_states,
        initial=automaton.initial,
        edges=tuple(merge_parallel(edges)),
        num_acc=len(keep),
        state_names=automaton.state_names,
        formula=automaton.formula,
        state_based=automaton.state_based,
    )


def _drop_implied_sets(
    keep: list[int], components: Sequence[int], marks: Sequence[frozenset[int]]
) -> list[int]:
    """The sets of ``keep`` without those implied by another kept set in every accepting SCC.

    ``components[i]`` and ``marks[i]`` describe the i-th edge inside an accepting SCC.  When,
    in each accepting SCC, some other kept set is only carried by edges that carry ``b``, a
    cycle there that sees that set infinitely often sees ``b`` too, and one that misses ``b``
    misses that set: dropping ``b`` changes no cycle's verdict (Spot's ``scc_filter`` does
    the same).  A dropped set keeps a witness among the kept sets: a witness dropped later has
    a witness of its own, whose carriers are fewer still."""
    if len(keep) < 2:
        return keep
    carriers: dict[tuple[int, int], set[int]] = defaultdict(set)
    for i, (component, edge_marks) in enumerate(zip(components, marks, strict=True)):
        for mark in edge_marks:
            carriers[(component, mark)].add(i)
    groups = set(components)
    kept = list(keep)
    for mark in keep:
        others = [m for m in kept if m != mark]
        if others and all(
            any(carriers[(c, other)] <= carriers[(c, mark)] for other in others) for c in groups
        ):
            kept.remove(mark)
    return kept


def _merge_states(automaton: Automaton, letters: Sequence[frozenset[str]] | None) -> Automaton:
    """Quotient by the coarsest partition where equivalent states have equal signatures."""
    n = automaton.num_states
    # Each edge as (label, marks, target): the label is an interned guard, or with letters
    # every letter that enables the edge, so that a refinement round hashes small integers
    # and not formulas.  A signature is the set of (label, marks, target block) triples: it
    # tells the same states apart as grouping the labels by (marks, target block).
    labels: dict[Formula, int] = {}
    mark_ids: dict[frozenset[int], int] = {}
    out: list[list[tuple[int, int, int]]] = [[] for _ in range(n)]
    for edge in automaton.edges:
        marks = mark_ids.setdefault(edge.marks, len(mark_ids))
        if letters is None:
            label = labels.setdefault(edge.guard, len(labels))
            out[edge.src].append((label, marks, edge.dst))
        else:
            for i, letter in enumerate(letters):
                if holds(edge.guard, letter):
                    out[edge.src].append((i, marks, edge.dst))
    block = [0] * n
    while True:
        signatures: dict[object, int] = {}
        new_block = [0] * n
        for state in range(n):
            signature = frozenset((label, marks, block[dst]) for label, marks, dst in out[state])
            key = (block[state], signature)
            new_block[state] = signatures.setdefault(key, len(signatures))
        if len(set(new_block)) == len(set(block)):
            break
        block = new_block
    if len(set(block)) == n:
        return automaton
    representative: dict[int, int] = {}
    for state in range(n):
        representative.setdefault(block[state], state)
    keep = set(representative.values())
    edges = merge_parallel(
        [
            Edge(
                src=e.src,
                dst=representative[block[e.dst]],
                guard=e.guard,
                marks=e.marks,
            )
            for e in automaton.edges
            if e.src in keep
        ]
    )
    initial_rep = representative[block[automaton.initial]]
    merged = Automaton(
        aps=automaton.aps,
        num_states=n,
        initial=initial_rep,
        edges=tuple(edges),
        num_acc=automaton.num_acc,
        state_names=automaton.state_names,
        formula=automaton.formula,
        state_based=automaton.state_based,
    )
    return _renumber(merged, merged.edges, keep)


def reduce_by_simulation(
    automaton: Automaton, letters: Sequence[frozenset[str]] | None, deadline: float
) -> Automaton:
    """Quotient by direct-simulation equivalence, then prune dominated edges (see
    :mod:`tlmpc.automata.simulation`); the input unchanged when the deadline passes first."""
    if letters is None and len(automaton.aps) > simulation.MAX_APS:
        return automaton
    alphabet = simulation.Alphabet(automaton.aps, letters)
    current = automaton
    try:
        for saturated in (False, True):
            current = _simulation_round(current, alphabet, deadline, saturated=saturated)
        for saturated in (False, True):
            current = _simulation_round(
                current, alphabet, deadline, saturated=saturated, reverse=True
            )
        stripped = simulation.strip_transient(
            current, sccs(current.num_states, current.edges, current.initial)
        )
        current = simulation.merge_transient(
            stripped,
            alphabet,
            sccs(stripped.num_states, stripped.edges, stripped.initial),
            deadline,
        )
    except work.OutOfBudget:
        pass
    return current


def _simulation_round(
    automaton: Automaton,
    alphabet: simulation.Alphabet,
    deadline: float,
    *,
    saturated: bool | None,
    reverse: bool = False,
) -> Automaton:
    """One quotient-and-prune pass.  Edges between SCCs carry no marks after trimming; with
    ``saturated`` they carry every mark instead (both are the same language, since a run takes
    such an edge once): the bare marks let those edges be dominated, every mark lets them
    dominate, and each finds reductions the other misses.  With ``reverse``, by reverse
    simulation (states with the same pasts) instead of direct simulation.  With ``saturated``
    None, the edges between SCCs keep the marks they have (see :func:`_simulated_as_built`)."""
    relate: Callable[[Automaton, simulation.Alphabet, float], list[list[bool]]]
    merge: Callable[[Automaton, list[list[bool]]], Automaton]
    drop: Callable[[Automaton, simulation.Alphabet, list[list[bool]], float], Automaton]
    if reverse:
        relate = simulation.cosimulation
        merge = simulation.quotient_reverse
        drop = simulation.prune_reverse
    else:
        relate = simulation.simulation
        merge = simulation.quotient
        drop = simulation.prune

    def prepared(current: Automaton) -> Automaton:
        if saturated is None:
            return current
        component = sccs(current.num_states, current.edges, current.initial)
        if saturated:
            return simulation.saturate(current, component)
        return simulation.strip_transient(current, component)

    current = prepared(automaton)
    relation = relate(current, alphabet, deadline)
    merged = merge(current, relation)
    if merged is not current:
        merged = merge_parallel_automaton(merged)
        keep = {e.src for e in merged.edges} | {e.dst for e in merged.edges} | {merged.initial}
        current = prepared(_renumber(merged, merged.edges, keep))
        relation = relate(current, alphabet, deadline)
    return drop(current, alphabet, relation, deadline)


#: Work units the other starting points of :func:`postprocess` always get under a share.
START_FLOOR = 200_000


def postprocess(
    automaton: Automaton,
    letters: Sequence[frozenset[str]] | None,
    deadline: float | None = None,
    *,
    obligation: bool = False,
    verify: Callable[[Automaton, Automaton], bool] | None = None,
    start_share: float | None = None,
) -> Automaton:
    """The smallest of the reductions of :func:`reduce_automaton` started from ``automaton``
    and, while ``deadline`` allows, from the other starting points of :data:`STARTS`.

    Simulation-based reduction is a local search: which states end up merged depends on the
    order of the steps and on the marks of the edges between SCCs (which do not change the
    language, but do change which states simulate which).  Each start is a correct automaton
    of the same language, so the smallest result is too.  With ``start_share``, the other
    starts together get at most that multiple of the first reduction's work (but at least
    :data:`START_FLOOR`), and skip the WDBA step (a planner's translation: a few states
    seldom pay for a slower compile)."""
    started = work.spent()
    best = reduce_automaton(automaton, letters, deadline, obligation=obligation, verify=verify)
    limit = deadline if deadline is not None else float("inf")
    if start_share is not None:
        # Never less than START_FLOOR: small automata (most missions) then always get every
        # start, so their result does not depend on the machine's speed.
        share = max(start_share * (work.spent() - started), START_FLOOR)
        limit = min(limit, work.spent() + share)
    first = work.spent() - started
    for start in STARTS:
        # A start costs about what the first reduction did: none begins that cannot end
        # before the limit (so the limit is not overrun by the steps that do not check it).
        if best.num_states <= 1 or work.spent() + first > limit:
            break
        candidate = reduce_automaton(
            start(automaton, letters, limit),
            letters,
            limit,
            obligation=obligation and start_share is None,
            verify=verify if start_share is None else None,
        )
        if (candidate.num_states, len(candidate.edges)) < (best.num_states, len(best.edges)):
            best = candidate
    return best


def _simulated_as_built(
    automaton: Automaton,
    letters: Sequence[frozenset[str]] | None,
    deadline: float,
    *,
    reduce_sets: bool = False,
) -> Automaton:
    """Direct, reverse and direct simulation before anything else: the edges between SCCs
    keep the marks the construction gave them (postponed eventualities), which trimming
    drops; under them some states simulate others that neither bare nor saturated marks
    relate.  With ``reduce_sets``, first trimmed and with its acceptance sets reduced, the
    edges entering an accepting SCC keeping their marks (Spot's order: ``scc_filter``, then
    ``simulation``).  The relation is a direct simulation of the automaton with exactly
    these marks (which has the same language: a run takes an edge between SCCs once), so
    the quotient and the pruning are sound even where merging closes a cycle through such
    an edge."""
    if letters is None and len(automaton.aps) > simulation.MAX_APS:
        return automaton
    alphabet = simulation.Alphabet(automaton.aps, letters)
    current = merge_parallel_automaton(automaton)
    if reduce_sets:
        current = _reduce_marks(trim(current, keep_transient_marks=True), keep_transient_marks=True)
    try:
        for reverse in (False, True, False):
            current = _simulation_round(
                current, alphabet, deadline, saturated=None, reverse=reverse
            )
            current = merge_parallel_automaton(current)
    except work.OutOfBudget:
        pass
    return current


def _trimmed_and_simulated(
    automaton: Automaton, letters: Sequence[frozenset[str]] | None, deadline: float
) -> Automaton:
    """Simulation to a fixpoint on the trimmed automaton, before the state merging and the
    reduction of acceptance sets (which may join states that simulation would have reduced
    differently)."""
    current = trim(merge_parallel_automaton(automaton))
    for _ in range(4):
        before = (current.num_states, len(current.edges), current.num_acc)
        current = reduce_by_simulation(current, letters, deadline)
        current = trim(merge_parallel_automaton(current))
        if (current.num_states, len(current.edges), current.num_acc) == before:
            break
    return current


#: Other starting points of :func:`postprocess`.
STARTS: tuple[Callable[[Automaton, Sequence[frozenset[str]] | None, float], Automaton], ...] = (
    _simulated_as_built,
    functools.partial(_simulated_as_built, reduce_sets=True),
    _trimmed_and_simulated,
)


def reduce_automaton(
    automaton: Automaton,
    letters: Sequence[frozenset[str]] | None,
    deadline: float | None = None,
    *,
    obligation: bool = False,
    verify: Callable[[Automaton, Automaton], bool] | None = None,
) -> Automaton:
    """Trim, prune SCCs, reduce acceptance sets and merge equivalent states (to a fixpoint),
    then reduce by direct simulation while the work count (:mod:`tlmpc.automata.work`) is under
    ``deadline``.

    Then the minimized weak deterministic automaton replaces the result: for a syntactic
    ``obligation`` when it is not larger, otherwise when it has fewer states and
    ``verify(result, candidate)`` shows both recognize the same language."""
    current = Automaton(
        aps=automaton.aps,
        num_states=automaton.num_states,
        initial=automaton.initial,
        edges=tuple(merge_parallel(automaton.edges)),
        num_acc=automaton.num_acc,
        state_names=automaton.state_names,
        formula=automaton.formula,
        state_based=automaton.state_based,
    )
    for _ in range(8):
        before = (current.num_states, len(current.edges), current.num_acc)
        current = trim(current)
        current = _reduce_marks(current)
        current = _merge_states(current, letters)
        if (current.num_states, len(current.edges), current.num_acc) == before:
            break
    for _ in range(4):
        if deadline is not None and work.over(deadline):
            break
        before = (current.num_states, len(current.edges), current.num_acc)
        current = reduce_by_simulation(
            current, letters, deadline if deadline is not None else float("inf")
        )
        current = merge_parallel_automaton(current)
        current = trim(current)
        current = _reduce_marks(current)
        current = _merge_states(current, letters)
        if (current.num_states, len(current.edges), current.num_acc) == before:
            break
    worth_trying = obligation or (verify is not None and current.num_states > 1)
    if worth_trying and (deadline is None or not work.over(deadline)):
        candidate = wdba.minimize_obligation(
            current, letters, deadline if deadline is not None else float("inf")
        )
        if candidate is not None:
            candidate = _merge_states(_reduce_marks(trim(candidate)), letters)
            if deadline is None or not work.over(deadline):
                # States on no cycle were told apart from the rest by the minimization's
                # acceptance flag, which does not matter for them: simulation merges them.
                reduced = reduce_by_simulation(
                    candidate, letters, deadline if deadline is not None else float("inf")
                )
                candidate = _merge_states(_reduce_marks(trim(reduced)), letters)
            if obligation:
                if (candidate.num_states, len(candidate.edges)) <= (
                    current.num_states,
                    len(current.edges),
                ) or candidate.num_states < current.num_states:
                    current = candidate
            elif (
                verify is not None
                and candidate.num_states < current.num_states
                and verify(current, candidate)
            ):
                current = candidate
    if letters is not None:
        current = _simplify_guards(current, letters)
    return current


def _simplify_guards(automaton: Automaton, letters: Sequence[frozenset[str]]) -> Automaton:
    """Shorten guards without changing which of ``letters`` enable them.

    Each cube drops literals while its set of enabled letters stays the same (with exclusive
    regions ``a & !b`` becomes ``a``); a guard every letter enables becomes ``true``.
    """

    def enabled(guard: Formula) -> int:
        """Bitmask of the letters that enable ``guard``."""
        mask = 0
        for i, letter in enumerate(letters):
            if holds(guard, letter):
                mask |= 1 << i
        return mask

    literal_masks: dict[Formula, int] = {}

    def cube_mask(literals: list[Formula]) -> int:
        # A conjunction of literals is enabled where all of them are: intersect cached masks.
        mask = everything
        for literal in literals:
            if literal not in literal_masks:
                literal_masks[literal] = enabled(literal)
            mask &= literal_masks[literal]
        return mask

    everything = (1 << len(letters)) - 1
    edges = []
    for edge in automaton.edges:
        target = enabled(edge.guard)
        if target == everything:
            edges.append(Edge(src=edge.src, dst=edge.dst, guard=TRUE, marks=edge.marks))
            continue
        parts = edge.guard.args if isinstance(edge.guard, Or) else (edge.guard,)
        shortened = []
        for part in parts:
            literals = _literals(part)
            if literals is None:
                shortened.append(part)
                continue
            kept = sorted(literals, key=str)
            mine = cube_mask(kept)
            for literal in list(kept):
                trial = [x for x in kept if x != literal]
                widened = cube_mask(trial)
                if widened & target == mine and widened & ~target == 0:
                    kept = trial
            shortened.append(conjoin(kept))
        guard = disjoin(_absorb(list(dict.fromkeys(shortened))))
        edges.append(Edge(src=edge.src, dst=edge.dst, guard=guard, marks=edge.marks))
    return dataclasses.replace(automaton, edges=tuple(edges))
