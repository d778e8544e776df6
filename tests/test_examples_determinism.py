"""A derandomized property draws the same examples in any run: alone, in its file, or in the
whole suite under xdist's work stealing (the conftest keeps Hypothesis from drawing the
numbers written in whatever local modules earlier tests happened to import)."""

from __future__ import annotations

import importlib

from hypothesis import given, settings
from hypothesis import strategies as st


def _drawn() -> list[float]:
    seen: list[float] = []

    @settings(max_examples=60, derandomize=True, database=None)
    @given(st.floats(-1e3, 1e3), st.integers(-1000, 1000))
    def collect(x: float, k: int) -> None:
        seen.append(x + k)

    collect()
    return seen


def test_examples_do_not_depend_on_the_modules_loaded() -> None:
    before = _drawn()
    # modules full of numbers the draws could pick up (thresholds, budgets, tolerances)
    for name in ("tlmpc.abstraction.lines", "tlmpc.planning.cells", "tlmpc.control.follow"):
        importlib.import_module(name)
    from hypothesis.internal.conjecture import providers

    assert len(providers._get_local_constants()) == 0
    assert _drawn() == before
