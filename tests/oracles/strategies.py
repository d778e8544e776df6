"""Hypothesis strategies for random LTL formulas and lasso words."""

from __future__ import annotations

from hypothesis import strategies as st

from tlmpc.ltl.ast import (
    FALSE,
    TRUE,
    And,
    Equiv,
    Eventually,
    Formula,
    Globally,
    Implies,
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
)

PROPS = ("a", "b", "c", "d")


def formulas(props: tuple[str, ...] = PROPS, max_leaves: int = 12) -> st.SearchStrategy[Formula]:
    """Random formulas over ``props`` using every operator."""
    leaves = st.one_of(st.sampled_from([Prop(p) for p in props]), st.sampled_from([TRUE, FALSE]))

    def extend(inner: st.SearchStrategy[Formula]) -> st.SearchStrategy[Formula]:
        binary = st.sampled_from([Until, Release, WeakUntil, StrongRelease, Implies, Equiv])
        return st.one_of(
            st.builds(Not, inner),
            st.builds(Eventually, inner),
            st.builds(Globally, inner),
            st.builds(lambda a, b: And((a, b)), inner, inner),
            st.builds(lambda a, b, c: Or((a, b, c)), inner, inner, inner),
            st.builds(lambda op, a, b: op(a, b), binary, inner, inner),
        )

    return st.recursive(leaves, extend, max_leaves=max_leaves)


@st.composite
def lassos(
    draw: st.DrawFn, props: tuple[str, ...] = PROPS, letters: list[frozenset[str]] | None = None
) -> tuple[list[frozenset[str]], int]:
    """A lasso word (letters, loop start); letters drawn from ``letters`` when given."""
    if letters is None:
        letter = st.frozensets(st.sampled_from(props), max_size=len(props))
    else:
        letter = st.sampled_from(letters)
    word = draw(st.lists(letter, min_size=1, max_size=7))
    loop = draw(st.integers(0, len(word) - 1))
    return word, loop
