"""The translation's budgets count work, not time: a hard formula translates to the same
automaton under a clock that races, one that stands still and the real one.

The formula is one of Spot's random formulas whose translation needs more work than its
budgets allow, so a budget cuts each translation short; a budget
read from any of the clocks would stop at once under the racing clock and never under the
frozen one.
"""

from __future__ import annotations

import importlib
import itertools
import time
from collections.abc import Callable

import pytest

from tlmpc.automata import to_hoa, translate, work
from tlmpc.automata.translate import DEFAULT_BUDGET
from tlmpc.ltl import parse_ltl

translate_module = importlib.import_module("tlmpc.automata.translate")

HARD = "(p3 R (G p3 W p1)) W ((G p0 R (p4 U F(p1 R p4))) R p0)"
CLOCKS = ("process_time", "perf_counter", "monotonic", "time", "thread_time")


def _racing() -> Callable[[], float]:
    ticks = itertools.count()
    return lambda: 3600.0 * next(ticks)  # an hour passes at every reading


def _translated(budget: int | None = DEFAULT_BUDGET) -> tuple[str, int]:
    before = work.spent()
    automaton = translate(parse_ltl(HARD), budget=budget)
    return to_hoa(automaton), work.spent() - before


def test_the_same_automaton_under_any_clock(monkeypatch: pytest.MonkeyPatch) -> None:
    real, units = _translated()
    with monkeypatch.context() as unlimited:
        for budget in ("CONTAINMENT_BUDGET", "WDBA_CHECK_BUDGET"):
            unlimited.setattr(translate_module, budget, float("inf"))
        # some budget cut the work short: where it did decides the result
        assert _translated(None)[1] > units
    for clock in CLOCKS:
        monkeypatch.setattr(time, clock, _racing())
    racing, racing_units = _translated()
    for clock in CLOCKS:
        monkeypatch.setattr(time, clock, lambda: 0.0)
    frozen, frozen_units = _translated()
    assert racing == real
    assert frozen == real
    assert racing_units == frozen_units == units


def test_a_charge_past_the_deadline_stops_the_work() -> None:
    deadline = work.spent() + 10
    work.charge(deadline, 10)
    assert not work.over(deadline)
    with pytest.raises(work.OutOfBudget):
        work.charge(deadline, 1)
    assert work.over(deadline)
