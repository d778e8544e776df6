"""Why no plan: the task's own satisfiability is translated once per task, not once per
mesh the planner tried (ten rooms took 77 CPU s to say P006, most of it the same question)."""

from __future__ import annotations

import importlib

import pytest

from tlmpc.ltl import parse_ltl
from tlmpc.planning.explain import satisfiable_anywhere


def test_the_task_is_translated_once_however_often_it_is_asked(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    translation = importlib.import_module("tlmpc.automata.translate")
    calls: list[str] = []
    original = translation.translate

    def counted(formula: object, **kw: object) -> object:
        calls.append(str(formula))
        return original(formula, **kw)

    monkeypatch.setattr(translation, "translate", counted)
    satisfiable_anywhere.cache_clear()
    task = parse_ltl("F a & F b & G (a -> b) & G !b")
    answers = {satisfiable_anywhere(task) for _ in range(8)}
    assert answers == {False}  # b can never hold, and a visit to b is asked
    assert len(calls) == 1
    assert satisfiable_anywhere(parse_ltl("F a & F b & G (a -> b)"))
    assert len(calls) == 2
