"""The closed convention in the planner: the rewritten task read on point/open words.

Under the closed convention the planner's automaton reads the task rewritten by
``closed_task`` on the discrete word point, open, point, ... with the marker ``POINT`` true at
points.  The rewrite must mean, on every such lasso, exactly what the continuous-time
definition (``tests/oracles/continuous_ltl.py``, independent of tlmpc) means at its first
instant.  Hypothesis draws formulas over every operator.
"""

from __future__ import annotations

import pytest
from continuous_ltl import Word, closed_holds
from hypothesis import given
from hypothesis import strategies as st
from lasso_ltl import holds
from strategies import formulas

from tlmpc.ltl.ast import And, Eventually, Formula, Not, Prop, Release, Until
from tlmpc.ltl.printer import to_text
from tlmpc.planning.boundary import POINT, closed_task

PROPS = ("a", "b", "c")
letters = st.frozensets(st.sampled_from(PROPS))


@st.composite
def piece_lassos(draw: st.DrawFn) -> tuple[Word, list[bool], int]:
    """Alternating pieces from a point piece: a loop that starts at a point piece and ends
    with an open piece, or a stay on the last (point) piece."""
    count = draw(st.integers(1, 5))
    stay = draw(st.booleans())
    size = 2 * count - 1 if stay else 2 * count
    word = draw(st.lists(letters, min_size=size, max_size=size))
    is_point = [k % 2 == 0 for k in range(size)]
    loop = size - 1 if stay else 2 * draw(st.integers(0, count - 1))
    return word, is_point, loop


@given(formulas(PROPS, max_leaves=7), piece_lassos())
def test_closed_task_means_the_continuous_definition(
    formula: Formula, lasso: tuple[Word, list[bool], int]
) -> None:
    word, is_point, loop = lasso
    marked = [
        letter | {POINT} if point else letter for letter, point in zip(word, is_point, strict=True)
    ]
    rewritten = closed_task(formula)
    for k in range(len(word)):
        if not is_point[k]:
            continue  # the rewrite is read from point instants (the start, each crossing)
        expected = closed_holds(formula, word, is_point, loop, k)
        assert holds(rewritten, marked, loop, k) == expected, (to_text(formula), k)


@given(formulas(PROPS, max_leaves=7), piece_lassos())
def test_rewrite_is_also_right_from_open_pieces(
    formula: Formula, lasso: tuple[Word, list[bool], int]
) -> None:
    """After the start, the product reads open pieces too (a triangle's interior)."""
    word, is_point, loop = lasso
    marked = [
        letter | {POINT} if point else letter for letter, point in zip(word, is_point, strict=True)
    ]
    rewritten = closed_task(formula)
    for k in range(len(word)):
        expected = closed_holds(formula, word, is_point, loop, k)
        assert holds(rewritten, marked, loop, k) == expected, (to_text(formula), k)


a, b = Prop("a"), Prop("b")


@pytest.mark.parametrize(
    ("formula", "word", "expected"),
    [
        # at a point in a, then an open stretch in b only: a U b needs a on part of it
        (Until(a, b), ["a", "b"], False),
        (Until(a, b), ["a", "ab"], True),
        (Until(a, b), ["b", ""], True),  # a witness at the point itself
        # !(a U b) as a release: !a R !b holds on the same word
        (Release(Not(a), Not(b)), ["a", "b"], True),
        (Release(Not(a), Not(b)), ["a", "ab"], False),
        (Eventually(And((a, b))), ["ab", "a"], True),  # F (a & b) holds at the point
    ],
)
def test_named_point_open_words(formula: Formula, word: list[str], expected: bool) -> None:
    """A point then an open stretch that stays forever (a loop on the open piece)."""
    letters_ = [frozenset(w) for w in word]
    is_point = [True, False]
    assert closed_holds(formula, letters_, is_point, 1, 0) is expected  # the definition
    marked = [letters_[0] | {POINT}, letters_[1]]
    assert holds(closed_task(formula), marked, 1, 0) is expected


@pytest.mark.parametrize(
    ("formula", "word", "expected"),
    [
        # b released at a later point where a holds: a R b is false there (!a U !b holds)
        (Release(a, b), ["b", "b", "a", "ab"], False),
        (Release(a, b), ["b", "b", "ab", "a"], True),
        # a U b with its witness at a later point where a fails: true (a on [t, s) only)
        (Until(a, b), ["a", "a", "b", ""], True),
        (Until(a, b), ["a", "", "b", ""], False),
    ],
)
def test_named_four_piece_lassos(formula: Formula, word: list[str], expected: bool) -> None:
    """point, open, point, open, looping from the second point."""
    letters_ = [frozenset(w) for w in word]
    is_point = [True, False, True, False]
    assert closed_holds(formula, letters_, is_point, 2, 0) is expected  # the definition
    marked = [x | {POINT} if p else x for x, p in zip(letters_, is_point, strict=True)]
    assert holds(closed_task(formula), marked, 2, 0) is expected
