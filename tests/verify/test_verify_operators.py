"""Every operator under both boundary conventions, and the three-valued verdict, against oracles.

Piece words alternate point and open pieces.  Under the right-continuous convention every
piece has a first instant, and the definition-level lasso evaluator of ``tests/oracles``
(discrete, non-strict until, by its definition) reads the word as it is.  Under the closed
convention, ``continuous_holds`` of ``tests/oracles/continuous_ltl.py`` states the
continuous-time definition on instants: every open piece contributes two instants, "just after
its start" and "later"; ``a U b`` at instant t holds iff some instant s >= t has b with a at
every instant in [t, s) — and s may be the "just after" instant of an open piece only when
s = t (there is no first instant after a point, so any later witness inside an open piece
leaves part of the piece in [t, s)).

The three-valued verdict of an open log is checked against LTL3 by brute force: every lasso
continuation of up to a few pieces must satisfy a prefix called good and violate one called
bad, and where the verdict is exact (each proposition used once) an inconclusive prefix must
have continuations both ways.  Spot confirms named cases.
"""

from __future__ import annotations

import itertools

import numpy as np
import numpy.typing as npt
import pytest
from continuous_ltl import closed_holds
from hypothesis import given
from hypothesis import strategies as st
from lasso_ltl import holds
from strategies import formulas

from tlmpc.ltl.ast import (
    And,
    Const,
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
from tlmpc.ltl.printer import to_text
from tlmpc.verify.evaluate import truth_atoms
from tlmpc.verify.semantics import evaluate, three_valued

PROPS = ("a", "b")
Word = list[frozenset[str]]
letters = st.frozensets(st.sampled_from(PROPS))
ALL_LETTERS = [frozenset(s) for n in range(3) for s in itertools.combinations(PROPS, n)]


def lasso_truth(
    formula: Formula,
    labels: npt.NDArray[np.bool_],
    names: list[str],
    loop_start: int,
    is_point: npt.NDArray[np.bool_] | None = None,
) -> npt.NDArray[np.bool_]:
    """Two-valued truth at every piece of a lasso, by the verifier's own evaluator."""
    lo, _ = evaluate(
        formula, truth_atoms(labels, names), labels.shape[0], loop_start, is_point=is_point
    )
    truth: npt.NDArray[np.bool_] = lo > 0
    return truth


def open_truth(
    formula: Formula,
    labels: npt.NDArray[np.bool_],
    names: list[str],
    is_point: npt.NDArray[np.bool_] | None = None,
) -> npt.NDArray[np.int8]:
    """Three-valued truth at every piece of a log that goes on, by the verifier's evaluator."""
    value = evaluate(
        formula, truth_atoms(labels, names), labels.shape[0], "open", is_point=is_point
    )
    return three_valued(value)


def _labels(word: Word) -> npt.NDArray[np.bool_]:
    return np.array([[p in letter for p in PROPS] for letter in word], dtype=bool).reshape(
        len(word), len(PROPS)
    )


@st.composite
def piece_lassos(draw: st.DrawFn) -> tuple[Word, list[bool], int]:
    """Alternating pieces from a point piece; either a loop from a point piece back over an
    open piece, or a stay on the last (point) piece."""
    count = draw(st.integers(1, 5))
    stay = draw(st.booleans())
    size = 2 * count - 1 if stay else 2 * count
    word = draw(st.lists(letters, min_size=size, max_size=size))
    is_point = [k % 2 == 0 for k in range(size)]
    loop = size - 1 if stay else 2 * draw(st.integers(0, count - 1))
    return word, is_point, loop


ALL_OPERATORS = formulas(PROPS, max_leaves=6)


@given(ALL_OPERATORS, piece_lassos())
def test_closed_convention_against_the_definition(
    formula: Formula, lasso: tuple[Word, list[bool], int]
) -> None:
    word, is_point, loop = lasso
    ours = lasso_truth(formula, _labels(word), list(PROPS), loop, np.array(is_point))
    # every piece, not only the first: sub-formula truth is checked all along the lasso
    for k in range(len(word)):
        expected = closed_holds(formula, word, is_point, loop, k)
        assert bool(ours[k]) == expected, (to_text(formula), k)


@given(ALL_OPERATORS, piece_lassos())
def test_right_convention_against_the_definition(
    formula: Formula, lasso: tuple[Word, list[bool], int]
) -> None:
    word, _, loop = lasso
    ours = lasso_truth(formula, _labels(word), list(PROPS), loop)
    for k in range(len(word)):
        assert bool(ours[k]) == holds(formula, word, loop, k), (to_text(formula), k)


a, b = Prop("a"), Prop("b")

#: One formula per operator with a two-piece word.
TWO_PIECE_CASES: list[tuple[Formula, list[str]]] = [
    (Not(a), ["a", "a"]),
    (And((a, b)), ["ab", "a"]),
    (Or((a, b)), ["", "a"]),
    (Implies(a, b), ["a", ""]),
    (Equiv(a, b), ["b", ""]),
    (Until(a, b), ["a", "b"]),
    (Release(a, b), ["b", "a"]),
    (WeakUntil(a, b), ["a", "a"]),
    (StrongRelease(a, b), ["b", "ab"]),
    (Eventually(b), ["", "b"]),
    (Globally(a), ["a", ""]),
]


def _word(text: list[str]) -> Word:
    return [frozenset(t) for t in text]


def test_each_operator_on_a_two_piece_stay() -> None:
    """A point, then an open piece forever: every operator under both conventions."""
    for formula, letters_ in TWO_PIECE_CASES:
        word = _word(letters_)
        closed = lasso_truth(formula, _labels(word), list(PROPS), 1, np.array([True, False]))
        assert bool(closed[0]) == closed_holds(formula, word, [True, False], 1, 0), to_text(formula)
        right = lasso_truth(formula, _labels(word), list(PROPS), 1)
        assert bool(right[0]) == holds(formula, word, 1), to_text(formula)


def test_closed_until_needs_the_open_piece_after_a_point() -> None:
    # point in a, then an open piece and a stay in b only.  Right: b from the next piece on, so
    # a U b.  Closed: a witness inside the open piece needs a on part of it, which fails.
    word = _word(["a", "b", "b"])
    is_point = np.array([True, False, True])
    assert lasso_truth(Until(a, b), _labels(word), list(PROPS), 2)[0]
    assert not lasso_truth(Until(a, b), _labels(word), list(PROPS), 2, is_point)[0]


# -- three-valued verdicts of open logs ----------------------------------------------------------


SPOT_LTL3 = """
import json, sys
import spot
answers = []
for prefix, text in json.load(sys.stdin):
    if spot.translate(f"({prefix}) & !({text})").is_empty():
        answers.append(1)
    elif spot.translate(f"({prefix}) & ({text})").is_empty():
        answers.append(-1)
    else:
        answers.append(0)
print(json.dumps(answers))
"""


def _ltl3_by_spot(cases: list[tuple[Formula, Word]]) -> list[int]:
    """LTL3 by Spot: +1 every continuation satisfies, -1 none does, 0 otherwise.

    Spot runs in its own process (importing it inside the test process crashes it).
    """
    import json
    import subprocess
    import sys

    queries = []
    for formula, word in cases:
        prefix = ""
        for letter in reversed(word):
            literal = " & ".join(p if p in letter else f"!{p}" for p in PROPS)
            prefix = f"({literal}) & X({prefix})" if prefix else f"({literal})"
        queries.append((prefix, to_text(formula)))
    done = subprocess.run(
        [sys.executable, "-c", SPOT_LTL3],
        input=json.dumps(queries),
        capture_output=True,
        text=True,
        check=True,
    )
    answers: list[int] = json.loads(done.stdout)
    return answers


def _uses_each_prop_once(formula: Formula) -> bool:
    leaves = [n.name for n in formula.walk() if isinstance(n, Prop)]
    consts = any(isinstance(n, Const) for n in formula.walk())
    equiv = any(isinstance(n, Equiv) for n in formula.walk())
    return len(leaves) == len(set(leaves)) and not consts and not equiv


RIGHT_TAILS = [
    (list(tail), loop)
    for n in (1, 2, 3)
    for tail in itertools.product(ALL_LETTERS, repeat=n)
    for loop in range(n)
]


@given(ALL_OPERATORS, st.lists(letters, min_size=1, max_size=4))
def test_open_verdict_right_by_brute_force(formula: Formula, word: Word) -> None:
    ours = int(open_truth(formula, _labels(word), list(PROPS))[0])
    outcomes = {holds(formula, word + tail, len(word) + loop) for tail, loop in RIGHT_TAILS}
    if ours == 1:
        assert outcomes == {True}, to_text(formula)
    elif ours == -1:
        assert outcomes == {False}, to_text(formula)
    elif _uses_each_prop_once(formula):
        # no two obligations about one region can contradict (or complete) each other
        assert outcomes == {True, False}, to_text(formula)


def test_open_verdicts_named() -> None:
    word = _word(["a", "a", "b", ""])
    cases = {
        "F b": 1,
        "G F b": 0,
        "G !b": -1,
        "a U b": 1,
        "a U (a & b)": -1,
        "F G b": 0,
        "b R !a": -1,
        "!b R a": 1,
        "a W b": 1,
        "b M a": -1,
        "G(a -> F b)": 0,
        "F(b & F !b) | G a": 1,
    }
    from tlmpc.ltl.parser import parse_ltl

    formulas_ = [parse_ltl(text) for text in cases]
    spot_says = _ltl3_by_spot([(f, word) for f in formulas_])
    for (text, expected), formula, exact in zip(cases.items(), formulas_, spot_says, strict=True):
        assert int(open_truth(formula, _labels(word), list(PROPS))[0]) == expected, text
        assert exact == expected, text


def _continuations(length: int, closed: bool) -> list[tuple[Word, list[bool], int]]:
    """Every lasso continuation of ``length`` pieces.

    Closed: open, point, open, ...; it ends in a stay on a point piece, or loops from a point
    piece round to an open one.  Right: any letters, any loop.
    """
    found: list[tuple[Word, list[bool], int]] = []
    for letters_ in itertools.product(ALL_LETTERS, repeat=length):
        is_point = [(k % 2 == 1) if closed else False for k in range(length)]
        if not closed:
            found.extend((list(letters_), is_point, loop) for loop in range(length))
        elif length % 2 == 1:
            found.append((list(letters_), is_point, length - 1))
        else:
            found.extend((list(letters_), is_point, loop) for loop in range(1, length, 2))
    return found


CONTINUATIONS = [c for n in (1, 2, 3, 4) for c in _continuations(n, closed=True)]


@pytest.mark.slow
@given(formulas(PROPS, max_leaves=4), st.lists(letters, min_size=1, max_size=3))
def test_open_verdict_is_sound_on_closed_pieces_by_brute_force(
    formula: Formula, start: Word
) -> None:
    # a finite piece word ending in a point piece
    word = start + start[:1] if len(start) % 2 == 0 else start
    is_point = [k % 2 == 0 for k in range(len(word))]
    ours = int(open_truth(formula, _labels(word), list(PROPS), np.array(is_point))[0])
    if ours == 0:
        return
    for tail, tail_points, loop in CONTINUATIONS:
        full = word + tail
        points = is_point + tail_points
        assert closed_holds(formula, full, points, len(word) + loop, 0) == (ours == 1), to_text(
            formula
        )


def test_until_wraps_around_the_loop() -> None:
    # the only b is the loop's first piece: from every later piece, a U b needs the wrap
    word = _word(["b", "a", "a", "a"])
    for is_point in (None, np.array([True, False, True, False])):
        truth = lasso_truth(Until(a, b), _labels(word), list(PROPS), 0, is_point)
        assert truth.tolist() == [True, True, True, True]
        released = lasso_truth(Release(Not(a), Not(b)), _labels(word), list(PROPS), 0, is_point)
        assert released.tolist() == [False, False, False, False]
