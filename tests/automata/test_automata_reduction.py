"""Simulation-based reductions against definition-level oracles.

* ``simulation`` (bitsets over letter atoms) computes exactly the largest direct simulation as
  its definition states it, letter by letter (a naive fixpoint written here), with and
  without the initial-state condition of the reverse simulation.
* Every reduction — direct and reverse quotient, direct and reverse little brothers, the whole
  iterated chain — keeps the language of random automata, checked on random lasso words by the
  acceptance oracle of ``automata_oracles`` (independent of the reductions).
* Hand-built cases: the initial state is reverse-simulated by itself only, and a state reverse
  simulation merges although direct simulation cannot.
"""

from __future__ import annotations

from automata_oracles import accepts
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.automata.model import Automaton, Edge
from tlmpc.automata.simplify import reduce_by_simulation, sccs
from tlmpc.automata.simulation import (
    Alphabet,
    cosimulation,
    prune,
    prune_reverse,
    quotient,
    quotient_reverse,
    saturate,
    simulation,
    transpose,
)
from tlmpc.ltl.ast import TRUE, And, Formula, Not, Or, Prop

APS = ("a", "b")
VALUATIONS = [frozenset(), frozenset({"a"}), frozenset({"b"}), frozenset({"a", "b"})]
GUARDS: list[Formula] = [
    TRUE,
    Prop("a"),
    Not(Prop("a")),
    Prop("b"),
    And((Prop("a"), Not(Prop("b")))),
    Or((Prop("b"), Not(Prop("a")))),
]
FAR = 1e18


@st.composite
def automata(draw: st.DrawFn) -> Automaton:
    n = draw(st.integers(1, 5))
    k = draw(st.integers(0, 2))
    edge = st.builds(
        Edge,
        src=st.integers(0, n - 1),
        dst=st.integers(0, n - 1),
        guard=st.sampled_from(GUARDS),
        marks=st.frozensets(st.integers(0, k - 1)) if k else st.just(frozenset()),
    )
    edges = tuple(draw(st.lists(edge, max_size=12)))
    return Automaton(aps=APS, num_states=n, initial=0, edges=edges, num_acc=k)


letters = st.sampled_from(VALUATIONS)
words = st.tuples(st.lists(letters, max_size=3), st.lists(letters, min_size=1, max_size=4))


def _holds(guard: Formula, letter: frozenset[str]) -> bool:
    if guard == TRUE:
        return True
    if isinstance(guard, Prop):
        return guard.name in letter
    if isinstance(guard, Not):
        return not _holds(guard.arg, letter)
    if isinstance(guard, And):
        return all(_holds(a, letter) for a in guard.args)
    assert isinstance(guard, Or)
    return any(_holds(a, letter) for a in guard.args)


def naive_simulation(automaton: Automaton, initial: int | None = None) -> list[list[bool]]:
    """The definition: q simulates p iff for every edge p --l/M--> p' and every letter l of
    it, some edge q --l/M'--> q' has M ⊆ M' and q' simulating p' (greatest fixpoint)."""
    n = automaton.num_states
    sim = [[True] * n for _ in range(n)]
    if initial is not None:
        sim[initial] = [q == initial for q in range(n)]
    changed = True
    while changed:
        changed = False
        for p in range(n):
            for q in range(n):
                if p == q or not sim[p][q]:
                    continue
                for e in automaton.edges:
                    if e.src != p:
                        continue
                    for letter in VALUATIONS:
                        if not _holds(e.guard, letter):
                            continue
                        if not any(
                            f.src == q
                            and _holds(f.guard, letter)
                            and e.marks <= f.marks
                            and sim[e.dst][f.dst]
                            for f in automaton.edges
                        ):
                            sim[p][q] = False
                            changed = True
                            break
                    if not sim[p][q]:
                        break
    return sim


@given(automata())
def test_simulation_is_the_largest_direct_simulation(automaton: Automaton) -> None:
    alphabet = Alphabet(APS, None)
    assert simulation(automaton, alphabet, FAR) == naive_simulation(automaton)
    reverse = cosimulation(automaton, alphabet, FAR)
    assert reverse == naive_simulation(transpose(automaton), initial=automaton.initial)


def _same_language(
    before: Automaton, after: Automaton, samples: list[tuple[list[frozenset[str]], ...]]
) -> None:
    for prefix, loop in samples:
        assert accepts(after, prefix, loop) == accepts(before, prefix, loop), (
            before,
            after,
            prefix,
            loop,
        )


@given(automata(), st.lists(words, min_size=1, max_size=10), st.booleans())
def test_each_reduction_keeps_the_language(
    automaton: Automaton,
    samples: list[tuple[list[frozenset[str]], ...]],
    saturated: bool,
) -> None:
    alphabet = Alphabet(APS, None)
    if saturated:  # every mark on the edges between SCCs: the same language
        component = sccs(automaton.num_states, automaton.edges, automaton.initial)
        reachable = [c if c >= 0 else -1 - s for s, c in enumerate(component)]
        automaton = saturate(automaton, reachable)
    direct = simulation(automaton, alphabet, FAR)
    reverse = cosimulation(automaton, alphabet, FAR)
    for reduced in (
        quotient(automaton, direct),
        prune(automaton, alphabet, direct, FAR),
        quotient_reverse(automaton, reverse),
        prune_reverse(automaton, alphabet, reverse, FAR),
    ):
        _same_language(automaton, reduced, samples)


@given(automata(), st.lists(words, min_size=1, max_size=10))
def test_iterated_reduction_keeps_the_language(
    automaton: Automaton, samples: list[tuple[list[frozenset[str]], ...]]
) -> None:
    reduced = reduce_by_simulation(automaton, None, float("inf"))
    _same_language(automaton, reduced, samples)


def test_only_the_initial_state_reverse_simulates_the_initial_state() -> None:
    """0 (initial) and 1 both loop on a and read b into 2, which accepts b^ω.  Every prefix
    that reaches 1 also reaches 0, but the empty prefix reaches 0 only: 0 reverse-simulates
    1, not the other way round (merging them would let 1 start runs)."""
    a, b = Prop("a"), Prop("b")
    edges = (
        Edge(src=0, dst=0, guard=a),
        Edge(src=1, dst=1, guard=a),
        Edge(src=0, dst=2, guard=b),
        Edge(src=1, dst=2, guard=b),
        Edge(src=2, dst=2, guard=b, marks=frozenset({0})),
    )
    automaton = Automaton(aps=("a", "b"), num_states=3, initial=0, edges=edges, num_acc=1)
    relation = cosimulation(automaton, Alphabet(("a", "b"), None), FAR)
    assert relation[1][0]  # 0 reverse-simulates 1 (0 is reached by every prefix 1 is)
    assert not relation[0][1]


def test_reverse_simulation_merges_what_direct_simulation_cannot() -> None:
    """Two states reached by the same prefixes (0 reads a) but with different futures: 1
    reads a, 2 reads b, both into the accepting sink 3.  No direct simulation relates them;
    they reverse-simulate each other and merge into one state with both futures."""
    a, b = Prop("a"), Prop("b")
    edges = (
        Edge(src=0, dst=1, guard=a),
        Edge(src=0, dst=2, guard=a),
        Edge(src=1, dst=3, guard=a),
        Edge(src=2, dst=3, guard=b),
        Edge(src=3, dst=3, guard=TRUE, marks=frozenset({0})),
    )
    automaton = Automaton(aps=("a", "b"), num_states=4, initial=0, edges=edges, num_acc=1)
    alphabet = Alphabet(("a", "b"), None)
    direct = simulation(automaton, alphabet, FAR)
    assert not direct[1][2]
    assert not direct[2][1]
    reverse = cosimulation(automaton, alphabet, FAR)
    assert reverse[1][2]
    assert reverse[2][1]
    merged = quotient_reverse(automaton, reverse)
    assert len({e.dst for e in merged.edges}) == 2
    none: frozenset[str] = frozenset()
    ab, just_a, just_b = frozenset({"a", "b"}), frozenset({"a"}), frozenset({"b"})
    for prefix, loop, expected in (
        ([just_a, just_a], [none], True),
        ([just_a, just_b], [none], True),
        ([ab, ab], [ab], True),
        ([just_b], [none], False),
        ([just_a], [none], False),
        ([just_a, none], [ab], False),
    ):
        assert accepts(automaton, prefix, loop) is expected
        assert accepts(merged, prefix, loop) is expected
