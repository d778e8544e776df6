"""LTL (without X) → transition-based generalized Büchi automaton, Couvreur/Spot style.

States are conjunctions of NNF formulas (hash-consed tuples, implied conjuncts dropped).  The
one-step expansion of a state gives its edges: the letter constraint becomes the guard, the
next-obligations the target, and an edge belongs to acceptance set ``Acc[e]`` of eventuality
``e`` iff it does not postpone ``e``.  Then: dominated edges are removed, the automaton is
trimmed to the states that can reach an accepting cycle, marks on edges that lie on no cycle
are dropped, and states with the same outgoing behaviour are merged.  See docs/automata.md.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence

from tlmpc.automata import work
from tlmpc.automata.containment import simplify_by_containment
from tlmpc.automata.emptiness import equivalent_to_deterministic
from tlmpc.automata.model import Automaton, Edge
from tlmpc.automata.nnf import FALSE, Node
from tlmpc.automata.rewrite import MAX_SEMANTIC_APS, rewrite
from tlmpc.automata.simplify import postprocess
from tlmpc.automata.terms import (
    Expansion,
    TooManyTerms,
    combine,
    eventualities,
    expand,
    from_ast,
    restrict_letters,
    simplify_state,
    to_text,
)
from tlmpc.automata.wdba import is_obligation
from tlmpc.automata.work import OutOfBudget
from tlmpc.base.errors import UsageError, error
from tlmpc.base.graphs import csr, strong_components
from tlmpc.ltl.ast import Formula, Not, Prop, conjoin
from tlmpc.ltl.bounds import refuse_bounds
from tlmpc.ltl.printer import to_text as formula_text
from tlmpc.ltl.transform import nnf

#: Work units (:mod:`tlmpc.automata.work`) of optional reduction work per translation (see
#: :func:`translate`).  The budgets were seconds of CPU time once; a unit is about a fourth of a
#: microsecond of it (measured over Spot's random formulas), so this was half a second.
DEFAULT_BUDGET = 2_000_000
#: Over a map's letters (the planner's translation), the post-processing's other starting
#: points together get at most this multiple of the first reduction's work.
PLANNER_START_SHARE = 0.5
#: At most this much work for the language-containment simplification of the formula.
CONTAINMENT_BUDGET = 800_000

#: The work units of building and rewriting the internal form of a formula, per node of its
#: negation normal form, in the emptiness checks of the containment simplification (measured:
#: 20-70 µs a node, on formulas of 10 to 5,000 nodes).
UNITS_PER_NODE = 100

#: The translation refuses (P041) a formula whose automaton, before any reduction, has more
#: edges than this (each takes about 2.5 KiB until the reductions are done: about 750 MiB), or
#: a state more than :data:`~tlmpc.automata.terms.MAX_TERMS` expansion terms.
MAX_RAW_EDGES = 300_000
#: ... or whose states, before any reduction, take more work units than this to expand (each
#: state its terms, their obligations and promises, and their pairwise domination check): many
#: independent goals over a map's exclusive letters (`visit p0, ..., visit p13`: 16,384 states)
#: stay under the edges' budget while their exploration takes minutes.
MAX_EXPLORATION_UNITS = 1_000_000

#: Emptiness checks of the rewriting give up (answer "not shown empty") past this many states.
MAX_EMPTINESS_STATES = 400

#: At most this much work for each equivalence check of a WDBA-minimized automaton (a formula
#: that is not a syntactic obligation may still have one; the check decides).
WDBA_CHECK_BUDGET = 400_000

#: Above this many expansion terms in one state, dominated terms are left to the simulation.
MAX_DOMINATION_TERMS = 600

#: The same for each partial product of a state's conjuncts (checked more often).
MAX_PARTIAL_DOMINATION_TERMS = 150

State = frozenset[Node]
Cube = tuple[frozenset[str], frozenset[str]]


def cube_formula(pos: Iterable[str], neg: Iterable[str]) -> Formula:
    """The conjunction of literals of a cube (``true`` for the empty cube)."""
    literals: list[Formula] = [Prop(p) for p in sorted(pos)]
    literals += [Not(Prop(n)) for n in sorted(neg)]
    return conjoin(literals)


def _dominated(terms: list[tuple[Cube, State, int]], num_acc: int) -> list[tuple[Cube, State, int]]:
    """Drop every term that another term dominates.

    Term A dominates B when A is enabled whenever B is (weaker cube), leaves a weaker
    obligation (a subset of B's conjuncts) and carries at least B's marks: any accepting run
    through B can go through A instead.  Among distinct terms the relation is a partial order,
    so the undominated terms remain.
    """
    unique = list(dict.fromkeys(terms))
    if len(unique) > MAX_DOMINATION_TERMS:
        # The check is quadratic; the simulation-based pruning later does the same job
        # within the time budget.
        return unique
    names = sorted({p for (pos, neg), _t, _m in unique for p in pos | neg})
    bit = {name: 1 << i for i, name in enumerate(names)}
    width = len(names)
    # Term A dominates B iff key(A) is a bit subset of key(B) and A's target a subset of B's:
    # key = positive literals | negative literals | marks *not* carried.
    every = (1 << num_acc) - 1
    keys = []
    for (pos, neg), _target, marks in unique:
        key = 0
        for p in pos:
            key |= bit[p]
        for n in neg:
            key |= bit[n] << width
        keys.append(key | (every & ~marks) << (2 * width))
    kept = []
    # Distinct terms cannot dominate each other both ways, so "any other term" is safe.
    for i, term in enumerate(unique):
        key, target = keys[i], term[1]
        for j, other in enumerate(unique):
            if j != i and keys[j] & ~key == 0 and other[1] <= target:
                break
        else:
            kept.append(term)
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
    budget: int | None = DEFAULT_BUDGET,
    containment: bool = True,
) -> Automaton:
    """Translate ``formula`` (no X) into a TGBA.

    Args:
        formula: the LTL formula.
        letters: when given, the only label sets that can occur (each the set of propositions
            true at once; all others false).  Edges no letter enables are dropped and states are
            merged with respect to these letters only.
        simplify: run the post-processing (trim, SCC pruning, merging).
        budget: work units (:mod:`tlmpc.automata.work`: counted operations, never time, so
            that the result is the same on any machine under any load) after which the
            optional reductions (simulation) stop and the automaton reduced so far, which is
            always correct, is returned; None = no limit.
        containment: simplify the formula by language containment first.

    Raises:
        UsageError: P041, the automaton is beyond the translation's budget before any
            reduction (:data:`MAX_RAW_EDGES` edges, or a state of
            :data:`~tlmpc.automata.terms.MAX_TERMS` terms).
    """
    refuse_bounds(formula, purpose="the automaton translation")
    return _translate(
        formula, letters=letters, simplify=simplify, budget=budget, containment=containment
    )


def _translate(
    formula: Formula,
    *,
    letters: Sequence[Sequence[str]] | None,
    simplify: bool,
    budget: float | None,
    containment: bool,
    check_wdba: bool = True,
    explore_deadline: float | None = None,
) -> Automaton:
    """:func:`translate`; with ``explore_deadline`` (a work count), :class:`OutOfBudget` is
    raised when the raw automaton is not built by then (for the optional checks that need one)."""
    started = work.spent()
    deadline = None if budget is None else started + budget
    original = formula
    if simplify and containment:
        # Half the budget at most for the containment checks (each one a small translation).
        share = CONTAINMENT_BUDGET if budget is None else min(CONTAINMENT_BUDGET, budget / 2)
        limit = started + share
        formula = simplify_by_containment(nnf(formula), lambda f: _is_empty(f, limit), limit)
    aps = tuple(sorted(original.props()))
    semantic = simplify and containment and len(aps) <= MAX_SEMANTIC_APS
    rewrite_deadline = work.spent() + (CONTAINMENT_BUDGET if budget is None else budget / 5)
    root = rewrite(
        from_ast(formula),
        (lambda f: _is_empty_term(f, rewrite_deadline)) if semantic else None,
        rewrite_deadline,
    )
    letter_sets = (
        None
        if letters is None
        else list(dict.fromkeys(frozenset(x for x in letter if x in aps) for letter in letters))
    )
    events = eventualities(root)
    initial = simplify_state(frozenset([root])) if root != FALSE else None
    previous_letters = restrict_letters(letter_sets)
    try:
        automaton = _explore(
            initial, events, letter_sets, formula_text(original), aps, explore_deadline
        )
    finally:
        restrict_letters(previous_letters)
    if simplify:
        verify = None
        if check_wdba:

            def verify(reduced: Automaton, candidate: Automaton) -> bool:
                # The negation's automaton, itself without this check (no recursion), built
                # within the check's own budget and the translation's deadline: past them
                # the candidate is simply not proved equivalent.
                limit: float = work.spent() + WDBA_CHECK_BUDGET
                if deadline is not None:
                    limit = min(limit, deadline)
                try:
                    negation = _translate(
                        Not(original),
                        letters=None if letter_sets is None else [sorted(x) for x in letter_sets],
                        simplify=True,
                        budget=WDBA_CHECK_BUDGET,
                        containment=False,
                        check_wdba=False,
                        explore_deadline=limit,
                    )
                except OutOfBudget:
                    return False
                limit = work.spent() + WDBA_CHECK_BUDGET
                if deadline is not None:
                    limit = min(limit, deadline)
                return equivalent_to_deterministic(reduced, candidate, negation, letter_sets, limit)

        automaton = postprocess(
            automaton,
            letter_sets,
            deadline,
            obligation=is_obligation(root),
            verify=verify,
            start_share=None if letter_sets is None else PLANNER_START_SHARE,
        )
    if letter_sets is not None:
        automaton = dataclasses.replace(
            automaton, letters=tuple(sorted(tuple(sorted(x)) for x in letter_sets))
        )
    return automaton


def _explore(
    initial: State | None,
    events: list[Node],
    letter_sets: list[frozenset[str]] | None,
    text: str,
    aps: tuple[str, ...],
    deadline: float | None = None,
) -> Automaton:
    """The raw TGBA: states reached from ``initial`` by the expansion terms letters allow
    (:class:`~tlmpc.automata.work.OutOfBudget` once the work count passes ``deadline``, when
    given).  Past :data:`MAX_RAW_EDGES` edges or :data:`~tlmpc.automata.terms.MAX_TERMS`
    terms in a state: :class:`~tlmpc.base.errors.UsageError` (P041), or with a ``deadline``
    (an optional check) :class:`~tlmpc.automata.work.OutOfBudget`."""
    event_index = {e: i for i, e in enumerate(events)}
    every = (1 << len(events)) - 1
    states: dict[State, int] = {}
    names: list[str] = []
    raw_edges: list[tuple[int, int, Cube, int]] = []
    explored = 0  # work units of the states expanded (MAX_EXPLORATION_UNITS)
    if initial is not None:
        states[initial] = 0
        names.append(_state_name(initial))
        queue = [initial]
        while queue:
            state = queue.pop()
            source = states[state]
            try:
                expansion = _state_terms(state)
            except TooManyTerms as exc:
                if deadline is not None:  # an optional check: it gives up
                    raise OutOfBudget from None
                raise _too_large(text, len(states), state_limit=exc.limit) from None
            units = _expansion_units(expansion)
            if deadline is not None:
                work.charge(deadline, units)
            explored += units
            if explored > MAX_EXPLORATION_UNITS:
                if deadline is not None:
                    raise OutOfBudget
                raise _too_large(text, len(states), explored=explored)
            terms: list[tuple[Cube, State, int]] = []
            for pos, neg, nxt, promises in expansion:
                target = simplify_state(nxt)
                if target is None or not _letter_ok((pos, neg), letter_sets):
                    continue
                terms.append(((pos, neg), target, _kept_marks(promises, event_index, every)))
            for cube, target, marks in _dominated(terms, len(events)):
                if target not in states:
                    states[target] = len(states)
                    names.append(_state_name(target))
                    queue.append(target)
                raw_edges.append((source, states[target], cube, marks))
            if len(raw_edges) > MAX_RAW_EDGES:
                if deadline is not None:
                    raise OutOfBudget
                raise _too_large(text, len(states))
    edges = tuple(
        Edge(
            src=s,
            dst=d,
            guard=cube_formula(*cube),
            marks=frozenset(i for i in range(marks.bit_length()) if marks >> i & 1),
        )
        for s, d, cube, marks in raw_edges
    )
    return Automaton(
        aps=aps,
        num_states=max(len(states), 1),
        initial=0,
        edges=edges,
        num_acc=len(events),
        state_names=tuple(names) if names else ("false",),
        formula=text,
    )


def _is_empty(formula: Formula, deadline: float = float("inf")) -> bool:
    """No word satisfies ``formula`` (see :func:`_is_empty_term`); not shown empty (False)
    when the work of bringing it to the internal form, :data:`UNITS_PER_NODE` for each of
    its nodes, would pass ``deadline``."""
    normal = nnf(formula)
    if work.over(deadline, UNITS_PER_NODE * sum(1 for _ in normal.walk())):
        return False
    return _is_empty_term(rewrite(from_ast(normal)), deadline)


def _is_empty_term(root: Node, deadline: float = float("inf")) -> bool:
    """No word satisfies the internal formula ``root``: no SCC of its raw automaton carries
    every acceptance set on its inner edges.  Over every letter (the caller's letter
    restriction is set aside meanwhile).  Only the graph is built (no guards, no reduction);
    past :data:`MAX_EMPTINESS_STATES` states or ``deadline`` the answer is False ("not
    shown empty"), which only leaves a rewriting unapplied."""
    if root == FALSE:
        return True
    initial = simplify_state(frozenset([root]))
    if initial is None:
        return True
    events = eventualities(root)
    event_index = {e: i for i, e in enumerate(events)}
    every = (1 << len(events)) - 1
    previous = restrict_letters(None)
    try:
        states: dict[State, int] = {initial: 0}
        queue = [initial]
        graph: list[tuple[int, int, int]] = []
        while queue:
            if len(states) > MAX_EMPTINESS_STATES:
                return False
            state = queue.pop()
            source = states[state]
            try:
                expansion = _state_terms(state)
            except TooManyTerms:
                return False
            if work.over(deadline, _expansion_units(expansion)):
                return False
            terms: list[tuple[Cube, State, int]] = []
            for pos, neg, nxt, promises in expansion:
                target = simplify_state(nxt)
                if target is None:
                    continue
                terms.append(((pos, neg), target, _kept_marks(promises, event_index, every)))
            for _cube, target, marks in _dominated(terms, len(events)):
                if target not in states:
                    states[target] = len(states)
                    queue.append(target)
                graph.append((source, states[target], marks))
    finally:
        restrict_letters(previous)
    succ: list[list[int]] = [[] for _ in range(len(states))]
    for src, dst, _bits in graph:
        succ[src].append(dst)
    component = strong_components(*csr(succ), [0])
    seen: dict[int, int] = {}
    for src, dst, bits in graph:
        if component[src] == component[dst]:
            seen[component[src]] = seen.get(component[src], 0) | bits
    return not any(bits == every for bits in seen.values())


def _kept_marks(promises: frozenset[Node], event_index: dict[Node, int], every: int) -> int:
    """The acceptance sets (bit ``i`` for eventuality ``i``) of a term postponing
    ``promises``: every eventuality it does not postpone."""
    postponed = 0
    for promise in promises:
        index = event_index.get(promise)
        if index is not None:
            postponed |= 1 << index
    return every & ~postponed


def _expansion_units(expansion: list[Expansion]) -> int:
    """The work units of one explored state: its terms, each with its obligations and
    promises, and their pairwise domination check."""
    terms = len(expansion)
    sizes = sum(len(term.next) + len(term.promises) for term in expansion)
    return 1 + terms + sizes + min(terms, MAX_DOMINATION_TERMS) ** 2


def _too_large(
    text: str, states: int, *, state_limit: int | None = None, explored: int | None = None
) -> UsageError:
    if explored is not None:
        too_many = f"states taking more than {MAX_EXPLORATION_UNITS:,} units of work to expand"
    elif state_limit is None:
        too_many = f"more than {MAX_RAW_EDGES:,} edges"
    else:
        too_many = f"a state with more than {state_limit:,} edges"
    return UsageError(
        error(
            "P041",
            f"the automaton of {_shortened(text)} has {too_many} before reduction "
            f"({states:,} state{'' if states == 1 else 's'} so far), more than the "
            "translation's budget",
            hint="split the task into smaller missions, or write fewer independent goals in "
            "one formula (each `F a` or `G F a` beside the others can double the automaton)",
        )
    )


def _shortened(text: str, limit: int = 120) -> str:
    return repr(text) if len(text) <= limit else repr(text[: limit - 1] + "…")


def _state_terms(state: State) -> list[Expansion]:
    """The expansion terms of ``state`` (:class:`TooManyTerms` past
    :data:`~tlmpc.automata.terms.MAX_TERMS`)."""
    terms: list[Expansion] = [Expansion(frozenset(), frozenset(), frozenset(), frozenset())]
    for part in sorted(state, key=repr):
        terms = _undominated_partial(combine(terms, expand(part)))
        if not terms:
            break
    return terms


def _merge_adjacent(terms: list[Expansion]) -> list[Expansion]:
    """Merge terms with the same obligations and promises whose cubes differ in the sign of
    one proposition only (``a & b`` and ``a & !b`` give ``a``), until none is left."""
    groups: dict[tuple[frozenset[Node], frozenset[Node]], set[Cube]] = {}
    for pos, neg, nxt, prom in terms:
        groups.setdefault((nxt, prom), set()).add((pos, neg))
    if len(groups) == len(terms):
        return terms
    out: list[Expansion] = []
    for (nxt, prom), cubes in groups.items():
        # In a canonical order (the cubes by their sorted literals, a cube's names sorted),
        # not the sets' own: that order follows the string hashes, which differ from one
        # process to the next, and which cubes merge first decides the result.
        changed = len(cubes) > 1
        while changed:
            changed = False
            for pos, neg in sorted(cubes, key=_cube_key):
                if (pos, neg) not in cubes:
                    continue
                for name in sorted(pos):
                    flipped = (pos - {name}, neg | {name})
                    if flipped in cubes:
                        cubes -= {(pos, neg), flipped}
                        cubes.add((pos - {name}, neg))
                        changed = True
                        break
        out.extend(Expansion(pos, neg, nxt, prom) for pos, neg in sorted(cubes, key=_cube_key))
    return out


def _cube_key(cube: Cube) -> tuple[list[str], list[str]]:
    return sorted(cube[0]), sorted(cube[1])


def _undominated_partial(terms: list[Expansion]) -> list[Expansion]:
    """Drop partial products dominated by another one (weaker cube, fewer obligations, fewer
    promises): whatever completes the dominated one completes the other one better, so
    pruning here keeps the product of the conjuncts from growing needlessly."""
    unique = _merge_adjacent(list(dict.fromkeys(terms)))
    if len(unique) < 2 or len(unique) > MAX_PARTIAL_DOMINATION_TERMS:
        return unique
    index: dict[tuple[str, str | Node], int] = {}
    keys = []
    for pos, neg, nxt, prom in unique:
        key = 0
        for name in pos:
            key |= 1 << index.setdefault(("p", name), len(index))
        for name in neg:
            key |= 1 << index.setdefault(("n", name), len(index))
        for node in nxt:
            key |= 1 << index.setdefault(("x", node), len(index))
        for node in prom:
            key |= 1 << index.setdefault(("P", node), len(index))
        keys.append(key)
    return [
        term
        for i, term in enumerate(unique)
        if not any(j != i and keys[j] & ~keys[i] == 0 for j in range(len(unique)))
    ]


def _state_name(state: State) -> str:
    if not state:
        return "true"
    return " & ".join(to_text(f) for f in sorted(state, key=repr))
