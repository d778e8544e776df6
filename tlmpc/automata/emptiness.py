"""Language inclusion between a deterministic automaton and a TGBA, by product emptiness.

Used to accept a WDBA-minimized automaton for a formula that is not a syntactic obligation
(Spot's ``minimize_obligation`` with its equivalence check): the candidate ``D``
(deterministic, from the subset construction) replaces the TGBA ``A`` of ``f`` only if

* ``L(A) ⊆ L(D)``: no word is accepted by ``A`` and rejected by ``D``.  ``D`` is
  deterministic, so it rejects a word iff its one run leaves it (completed by a rejecting sink)
  or sees its acceptance mark finitely often: the product ``A × D`` must have no reachable cycle
  that avoids ``D``'s mark and carries all of ``A``'s sets;
* ``L(D) ⊆ L(A)``: no word is accepted by ``D`` and by the TGBA of ``!f``: the product
  must have no reachable cycle carrying ``D``'s mark and every set of the negation's automaton.

Both are one search for a strongly connected component of a product graph whose internal
edges carry every required mark and none of the forbidden ones.
"""

from __future__ import annotations

from collections.abc import Sequence

from tlmpc.automata import work
from tlmpc.automata.model import Automaton
from tlmpc.automata.simulation import Alphabet
from tlmpc.base.graphs import csr, strong_components

#: Products with more nodes are not searched (the inclusion is then not established).
MAX_PRODUCT = 20_000

Moves = list[list[tuple[int, int, int]]]  # per state: (letter mask, mark bits, target)


def moves(automaton: Automaton, alphabet: Alphabet) -> Moves:
    """Per state, its edges as (letter mask, mark bitmask, target)."""
    out: Moves = [[] for _ in range(automaton.num_states)]
    for edge in automaton.edges:
        bits = 0
        for mark in edge.marks:
            bits |= 1 << mark
        out[edge.src].append((alphabet.mask(edge.guard), bits, edge.dst))
    return out


def _deterministic(row: list[tuple[int, int, int]]) -> bool:
    seen = 0
    for letters, _bits, _dst in row:
        if seen & letters:
            return False
        seen |= letters
    return True


def completed(deterministic: Moves, full: int) -> Moves:
    """``deterministic`` with a rejecting sink (the last state) taking every missing letter."""
    sink = len(deterministic)
    out = [list(row) for row in deterministic]
    for row in out:
        covered = 0
        for letters, _bits, _dst in row:
            covered |= letters
        if covered != full:
            row.append((full & ~covered, 0, sink))
    out.append([(full, 0, sink)])
    return out


def has_accepting_cycle(
    left: Moves,
    left_initial: int,
    left_sets: int,
    right: Moves,
    right_initial: int,
    right_sets: int,
    *,
    required: int,
    forbidden: int,
    deadline: float,
) -> bool | None:
    """Does the product of ``left`` and ``right`` (edges on common letters) reach a cycle whose
    edges carry every mark of ``required`` and none of ``forbidden``?  Marks are numbered
    ``left``'s first (``left_sets`` of them), then ``right``'s.  None: too large or too slow."""
    del right_sets  # the numbering needs only the left side's count
    shift = left_sets
    index = {(left_initial, right_initial): 0}
    nodes = [(left_initial, right_initial)]
    succ: list[list[tuple[int, int]]] = []
    for p, q in nodes:
        if len(nodes) > MAX_PRODUCT or work.over(deadline, 1 + len(left[p]) * len(right[q])):
            return None
        row: list[tuple[int, int]] = []
        for letters, bits, p2 in left[p]:
            for other_letters, other_bits, q2 in right[q]:
                if letters & other_letters == 0:
                    continue
                marks = bits | other_bits << shift
                key = (p2, q2)
                if key not in index:
                    index[key] = len(nodes)
                    nodes.append(key)
                row.append((index[key], marks))
        succ.append(row)
    # Only edges without a forbidden mark may lie on the cycle.
    allowed = [[t for t, marks in row if marks & forbidden == 0] for row in succ]
    component = strong_components(*csr(allowed))
    collected: dict[int, int] = {}
    for source, row in enumerate(succ):
        for target, marks in row:
            if marks & forbidden == 0 and component[source] == component[target]:
                collected[component[source]] = collected.get(component[source], 0) | marks
    return any(marks & required == required for marks in collected.values())


def equivalent_to_deterministic(
    automaton: Automaton,
    candidate: Automaton,
    negation: Automaton,
    letters: Sequence[frozenset[str]] | None,
    deadline: float,
) -> bool:
    """``L(candidate) = L(automaton)``, where ``candidate`` is deterministic with at most one
    acceptance set and ``negation`` is a TGBA of the formula's negation (all three over the
    same propositions and letters).  False when undecided within the deadline."""
    if candidate.num_acc > 1 or negation.aps != automaton.aps:
        return False
    alphabet = Alphabet(automaton.aps, letters)
    try:
        original = moves(automaton, alphabet)
        own = moves(candidate, alphabet)
        if candidate.num_acc == 0:  # every run accepts: as if every edge carried the mark
            own = [[(letters, 1, dst) for letters, _bits, dst in row] for row in own]
        if not all(_deterministic(row) for row in own):
            return False
        deterministic = completed(own, alphabet.full)
        everything = (1 << automaton.num_acc) - 1
        missed = has_accepting_cycle(
            original,
            automaton.initial,
            automaton.num_acc,
            deterministic,
            candidate.initial,
            1,
            required=everything,
            forbidden=1 << automaton.num_acc,
            deadline=deadline,
        )
        if missed is None or missed:
            return False
        negated = moves(negation, alphabet)
        extra = has_accepting_cycle(
            deterministic,
            candidate.initial,
            1,
            negated,
            negation.initial,
            negation.num_acc,
            required=1 | ((1 << negation.num_acc) - 1) << 1,
            forbidden=0,
            deadline=deadline,
        )
        return extra is False
    except work.OutOfBudget:
        return False
