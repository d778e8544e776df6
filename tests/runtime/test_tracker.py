"""The task tracker against a brute-force definition: after entering triangles labelled
w_1, ..., w_n, the tracked set is every state some run reaches reading w_1^k1 ... w_n^kn with
every k_i >= 1 (the robot stays a positive time in each triangle, so each label is read once
or more)."""

from __future__ import annotations

import itertools

from hypothesis import example, given, settings
from hypothesis import strategies as st

from tlmpc.automata.model import Automaton, Edge
from tlmpc.ltl.ast import Const, Formula, Not, Prop
from tlmpc.runtime.tracker import TaskTracker

LETTERS: tuple[tuple[str, ...], ...] = ((), ("a",), ("b",), ("a", "b"))
GUARDS: tuple[Formula, ...] = (
    Const(value=True),
    Prop(name="a"),
    Prop(name="b"),
    Not(arg=Prop(name="a")),
    Not(arg=Prop(name="b")),
)


@st.composite
def automata(draw: st.DrawFn) -> Automaton:
    states = draw(st.integers(1, 4))
    edges = draw(
        st.lists(
            st.tuples(
                st.integers(0, states - 1), st.integers(0, states - 1), st.sampled_from(GUARDS)
            ),
            max_size=10,
        )
    )
    return Automaton(
        aps=("a", "b"),
        num_states=states,
        initial=0,
        edges=tuple(Edge(src=s, dst=d, guard=g) for s, d, g in edges),
        num_acc=0,
    )


def _brute_force(automaton: Automaton, word: list[int]) -> frozenset[int]:
    """Every state reached over every stuttering of ``word`` (each letter up to n+1 times)."""
    from tlmpc.automata.guards import holds

    def step(states: set[int], letter: tuple[str, ...]) -> set[int]:
        return {e.dst for e in automaton.edges if e.src in states and holds(e.guard, set(letter))}

    reached: set[int] = set()
    limit = automaton.num_states + 1  # a longer stutter revisits a set already seen
    for repeats in itertools.product(range(1, limit + 1), repeat=len(word)):
        states = {automaton.initial}
        for letter, times in zip(word, repeats, strict=True):
            for _ in range(times):
                states = step(states, LETTERS[letter])
        reached |= states
    return frozenset(reached)


#: 0 -> 1 -> 2 on any letter: one letter read twice reaches 2 (a chain the drawn automata
#: make in about one case of ten, so it is also given outright).
CHAIN = Automaton(
    aps=("a", "b"),
    num_states=3,
    initial=0,
    edges=(
        Edge(src=0, dst=1, guard=Const(value=True)),
        Edge(src=1, dst=2, guard=Const(value=True)),
    ),
    num_acc=0,
)


@settings(max_examples=max(20, settings().max_examples // 2))
@given(automata(), st.lists(st.integers(0, len(LETTERS) - 1), min_size=1, max_size=3))
@example(CHAIN, [0])
def test_tracked_states_are_every_state_of_every_stuttering(
    automaton: Automaton, word: list[int]
) -> None:
    tracker = TaskTracker(automaton, LETTERS)
    states = tracker.initial(word[0])
    for letter in word[1:]:
        states = tracker.read(states, letter)
    assert states == _brute_force(automaton, word)
