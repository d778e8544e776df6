"""The closed convention in the planner: the rewritten task read on point/open words.

Under the closed convention the planner's automaton reads the task rewritten by
``closed_task`` on the discrete word point, open, point, ... with the marker ``POINT`` true at
points.  The rewrite must mean, on every such lasso, exactly what the continuous-time
definition (``tests/oracles/continuous_ltl.py``, independent of tlmpc) means at its first
instant.  Hypothesis draws formulas over every operator.
"""

from __future__ import annotations

from continuous_ltl import Word, closed_holds
from hypothesis import given
from hypothesis import strategies as st
from lasso_ltl import holds
from strategies import formulas

from tlmpc.ltl.ast import Formula
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
