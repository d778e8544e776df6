"""Time-bounded operators in dense time against the definition-level oracle.

``tests/oracles/dense_mtl.py`` evaluates MTL by its definition on a tick grid (exact when the
trace's instants and the bounds are multiples of a quantum).  Random piecewise traces (any
letter at any instant: both boundary conventions are special cases), stays and loops, and
random formulas mixing every bounded and untimed operator are checked at every instant of the
trace; inside an open piece the verifier reports the hull of the values there, which must
contain the oracle's.  Open logs (three-valued) must be sound: a verdict of satisfied or
violated must hold for every continuation drawn.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pytest
from dense_mtl import TickTrace, dense_values
from hypothesis import given, settings
from hypothesis import strategies as st
from strategies import bounded_formulas, intervals

from tlmpc.ltl.ast import BoundedUntil, Formula, Interval, Not, Or, Prop
from tlmpc.ltl.parser import parse_ltl
from tlmpc.ltl.printer import to_text
from tlmpc.verify.evaluate import truth_atoms
from tlmpc.verify.semantics import PieceEnding, Semantics, Timing, three_valued

PROPS = ("a", "b")
QUANTUM = 0.25
TICK = QUANTUM / 2

letters = st.frozensets(st.sampled_from(PROPS))


@st.composite
def tick_traces(draw: st.DrawFn, loop: bool | None = None) -> TickTrace:
    """Instants at multiples of the quantum, any letters; a stay or a loop."""
    gaps = draw(st.lists(st.sampled_from([2, 4, 6]), min_size=0, max_size=4))
    breaks = [0]
    for gap in gaps:
        breaks.append(breaks[-1] + gap)
    looping = draw(st.booleans()) if loop is None else loop
    count = 2 * len(breaks) - 1 + (1 if looping else 0)
    word = tuple(draw(st.lists(letters, min_size=count, max_size=count)))
    if not looping:
        return TickTrace(tuple(breaks), word)
    start = draw(st.integers(0, len(breaks) - 1))
    end = breaks[-1] + draw(st.sampled_from([2, 4]))
    return TickTrace(tuple(breaks), word, start, end)


def _labels(word: tuple[frozenset[str], ...]) -> npt.NDArray[np.bool_]:
    return np.array([[p in letter for p in PROPS] for letter in word], dtype=bool).reshape(
        len(word), len(PROPS)
    )


def ours(formula: Formula, trace: TickTrace, ending: PieceEnding | None = None) -> Semantics:
    """The verifier's evaluator on ``trace`` (``ending`` overrides: ``open``)."""
    starts = np.repeat(np.asarray(trace.breaks, dtype=np.float64) * TICK, 2)
    size = len(trace.letters)
    starts = starts[:size]
    is_point = np.zeros(size, dtype=bool)
    is_point[0::2] = True
    chosen: PieceEnding
    if ending is not None:
        chosen = ending
    elif trace.loop is None:
        chosen = "stay"
    else:
        chosen = 2 * trace.loop
    end = (trace.end if trace.end is not None else trace.breaks[-1]) * TICK
    return Semantics(
        truth_atoms(_labels(trace.letters), list(PROPS)),
        size,
        chosen,
        is_point=is_point,
        timing=Timing(starts, end),
    )


def _check(formula: Formula, trace: TickTrace) -> None:
    expected = dense_values(formula, trace, QUANTUM)
    lo, hi = ours(formula, trace)(formula)
    text = to_text(formula)
    last = trace.end if trace.end is not None else trace.breaks[-1]
    for index, when in enumerate(trace.breaks):
        assert lo[2 * index] == hi[2 * index], text
        assert (lo[2 * index] > 0) == expected[when], (text, trace, when)
        # inside the open piece after the instant: the hull holds the oracle's values
        following = trace.breaks[index + 1] if index + 1 < len(trace.breaks) else last
        if 2 * index + 1 < len(lo):
            inside = {expected[t] for t in range(when + 1, following)}
            if lo[2 * index + 1] > 0:
                assert inside == {True}, (text, trace, when)
            if hi[2 * index + 1] < 0:
                assert inside == {False}, (text, trace, when)
            if lo[2 * index + 1] < 0 < hi[2 * index + 1]:
                assert inside == {True, False}, (text, trace, when)


@settings(deadline=None)
@given(bounded_formulas(), tick_traces(loop=False))
def test_bounded_operators_on_stays_match_the_definition(
    formula: Formula, trace: TickTrace
) -> None:
    _check(formula, trace)


@settings(deadline=None)
@given(bounded_formulas(), tick_traces(loop=True))
def test_bounded_operators_on_loops_match_the_definition(
    formula: Formula, trace: TickTrace
) -> None:
    _check(formula, trace)


@st.composite
def continuations(draw: st.DrawFn, trace: TickTrace) -> TickTrace:
    """``trace`` (read as open) followed by more pieces, then a stay or a loop."""
    gaps = draw(st.lists(st.sampled_from([2, 4, 6]), min_size=0, max_size=3))
    breaks = list(trace.breaks)
    for gap in gaps:
        breaks.append(breaks[-1] + gap)
    extra = 2 * len(gaps)
    looping = draw(st.booleans())
    more = extra + (1 if looping else 0)
    word = trace.letters + tuple(draw(st.lists(letters, min_size=more, max_size=more)))
    if not looping:
        return TickTrace(tuple(breaks), word)
    start = draw(st.integers(len(trace.breaks) - 1, len(breaks) - 1))
    return TickTrace(tuple(breaks), word, start, breaks[-1] + draw(st.sampled_from([2, 4])))


@settings(deadline=None)
@given(bounded_formulas(max_leaves=4), tick_traces(loop=False), st.data())
def test_open_logs_are_sound(formula: Formula, trace: TickTrace, data: st.DataObject) -> None:
    verdict = int(three_valued(ours(formula, trace, "open")(formula))[0])
    if verdict == 0:
        return
    for _ in range(8):
        future = data.draw(continuations(trace))
        assert dense_values(formula, future, QUANTUM)[0] == (verdict == 1), to_text(formula)


def _trace(pieces: str, loop: int | None = None, end: int | None = None) -> TickTrace:
    """``"a@0 a b@2 - -@4"``-style: letter@tick for instants, bare letters for stretches."""
    breaks, word = [], []
    for item in pieces.split():
        letter, _, at = item.partition("@")
        word.append(frozenset(c for c in letter if c != "-"))
        if at:
            breaks.append(int(at))
    return TickTrace(tuple(breaks), tuple(word), loop, end)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        # a from 1 s to 2 s (ticks 8 to 16), closed at both ends; the log ends at 3 s
        ("F[0,1] a", 1),
        ("F[0,0.875] a", -1),  # the deadline passed inside the log: missed
        ("G[1,2] a", 1),
        ("G[1,2.125] a", -1),
        ("F[0,4] b", 0),  # not yet: the deadline is after the log's end
        ("F[0,2] b", -1),
        ("G[0,5] !b", 0),  # held so far
        ("a U[0,2] b", -1),
        ("!b U[0,4] b", 0),
    ],
)
def test_open_log_deadlines(text: str, expected: int) -> None:
    trace = _trace("-@0 - a@8 a a@16 - -@24")
    formula = parse_ltl(text)
    assert int(three_valued(ours(formula, trace, "open")(formula))[0]) == expected, text


def test_loop_deadline_over_the_wrap() -> None:
    # a at [1, 2] of every 3-s period: every window of 1 s + the gap of 1 s meets it
    trace = _trace("-@0 - a@8 a a@16 -", loop=0, end=24)
    assert ours(parse_ltl("G F[0,2] a"), trace).at_start(parse_ltl("G F[0,2] a"))[0] > 0
    assert ours(parse_ltl("G F[0,1.875] a"), trace).at_start(parse_ltl("G F[0,1.875] a"))[1] < 0


literals = st.sampled_from(
    [Prop("a"), Prop("b"), Not(Prop("a")), Not(Prop("b")), Or((Prop("a"), Prop("b")))]
)


@given(literals, literals, intervals, tick_traces())
def test_bounded_until_on_literals(
    left: Formula, right: Formula, interval: Interval, trace: TickTrace
) -> None:
    # single bounded untils, where the window's ends meet the instants of change most often
    _check(BoundedUntil(left, right, interval), trace)
