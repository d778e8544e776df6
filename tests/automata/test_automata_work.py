"""The translation's budgets count work, not time: a hard formula translates to the same
automaton under a clock that races, one that stands still and the real one.

The formula is one of Spot's random formulas whose translation needs more work than its
budgets allow, so a budget cuts each translation short; a budget
read from any of the clocks would stop at once under the racing clock and never under the
frozen one.
"""

from __future__ import annotations

import importlib
import io
import itertools
import time
from collections.abc import Callable

import pytest

from tlmpc.automata import terms, to_hoa, translate, work
from tlmpc.automata.terms import from_ast
from tlmpc.automata.translate import DEFAULT_BUDGET
from tlmpc.base.errors import UsageError
from tlmpc.cli import main
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


def _tree_size(node: object) -> int:
    """The nodes of an internal formula, shared subformulas counted at every occurrence."""
    children = [*getattr(node, "args", ())]
    children += [getattr(node, name) for name in ("arg", "left", "right") if hasattr(node, name)]
    return 1 + sum(_tree_size(child) for child in children if not isinstance(child, str))


def test_the_emptiness_checks_pay_for_their_domination_checks(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # A long until chain: the rewriting's emptiness checks meet states of hundreds of terms,
    # and each state's terms are compared pairwise.  That work is within the budget.
    compared = 0
    dominated = translate_module._dominated

    def counting(terms: list[object], num_acc: int) -> object:
        nonlocal compared
        compared += len(terms) ** 2
        return dominated(terms, num_acc)

    monkeypatch.setattr(translate_module, "_dominated", counting)
    translate(parse_ltl(" U ".join(f"p{i % 3}" for i in range(120))))
    assert 0 < compared <= DEFAULT_BUDGET


def test_the_containment_checks_pay_for_rewriting_their_formulas(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Each <-> doubles the negation normal form: the containment simplification meets
    # thousands of nodes, each a formula to rewrite before its emptiness check.
    text = "a"
    for index in range(10):
        text = f"({text} <-> b{index % 2})"
    rewritten = 0
    rewrite = translate_module.rewrite

    def counting(node: object, *args: object) -> object:
        nonlocal rewritten
        rewritten += _tree_size(node)
        return rewrite(node, *args)

    monkeypatch.setattr(translate_module, "rewrite", counting)
    formula = parse_ltl(text)
    own = _tree_size(translate_module.from_ast(formula))
    translate(formula)
    budget = translate_module.CONTAINMENT_BUDGET / translate_module.UNITS_PER_NODE
    assert rewritten <= budget + 2 * own


def test_an_automaton_beyond_the_budget_is_refused_before_it_is_built() -> None:
    # 17 independent recurrences: one state with 2^17 ways to proceed (every letter), which
    # would take gigabytes; refused from its first state.
    text = " & ".join(f"G F p{i}" for i in range(17))
    out, err = io.StringIO(), io.StringIO()
    assert main(["automaton", text], out=out, err=err) == 2
    assert "error[P041]" in err.getvalue()
    assert "a state with more than 100,000 edges" in err.getvalue()
    assert out.getvalue() == ""


def test_the_edges_before_reduction_are_counted(monkeypatch: pytest.MonkeyPatch) -> None:
    # F p0 & ... & F p5: 2^6 states, 3^6 = 729 edges before reduction
    formula = parse_ltl(" & ".join(f"F p{i}" for i in range(6)))
    monkeypatch.setattr(translate_module, "MAX_RAW_EDGES", 729)
    translate(formula)
    monkeypatch.setattr(translate_module, "MAX_RAW_EDGES", 728)
    with pytest.raises(UsageError) as refused:
        translate(formula)
    assert refused.value.diagnostics[0].code == "P041"
    assert "more than 728 edges" in refused.value.diagnostics[0].message


def test_one_formulas_expansion_stops_at_the_budget(monkeypatch: pytest.MonkeyPatch) -> None:
    # G(F p0 & ... & F p10): the conjunction alone has 2^11 terms
    node = from_ast(parse_ltl("G(" + " & ".join(f"F p{i}" for i in range(11)) + ")"))
    terms.expand.cache_clear()
    monkeypatch.setattr(terms, "MAX_TERMS", 2**11)
    assert len(terms.expand(node)) == 2**11
    terms.expand.cache_clear()
    monkeypatch.setattr(terms, "MAX_TERMS", 2**11 - 1)
    with pytest.raises(terms.TooManyTerms):
        terms.expand(node)
    terms.expand.cache_clear()


def test_one_states_expansion_stops_at_the_budget(monkeypatch: pytest.MonkeyPatch) -> None:
    # F p0 & ... & F p10: its first state has 11 conjuncts, two terms each, 2^11 together
    formula = parse_ltl(" & ".join(f"F p{i}" for i in range(11)))
    monkeypatch.setattr(translate_module, "MAX_RAW_EDGES", 10**9)
    monkeypatch.setattr(terms, "MAX_TERMS", 2**11 - 1)
    with pytest.raises(UsageError) as refused:
        translate(formula, containment=False)
    assert "a state with more than 2,047 edges" in refused.value.diagnostics[0].message
