"""The suite's own settings: the example budget follows CI, and nothing is timed."""

from __future__ import annotations

import os

from ci_oracles import in_ci
from conftest import FULL_EXAMPLES
from hypothesis import settings


def test_the_example_budget_follows_ci() -> None:
    chosen = os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if in_ci() else "dev")
    assert settings().max_examples == settings.get_profile(chosen).max_examples
    assert settings.get_profile("ci").max_examples == FULL_EXAMPLES
    assert 0 < settings.get_profile("dev").max_examples < FULL_EXAMPLES


def test_no_profile_has_a_deadline() -> None:
    for name in ("ci", "dev"):
        assert settings.get_profile(name).deadline is None
        assert settings.get_profile(name).derandomize
