"""Shared test configuration.

Hypothesis profiles: ``dev`` (default, thorough) and ``ci`` (smaller example budgets, never
zero), picked by ``HYPOTHESIS_PROFILE`` or, when unset, by the ``CI`` environment variable.
All profiles are derandomized so a failure reproduces on every machine.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile(
    "dev",
    max_examples=200,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "ci",
    max_examples=60,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(
    os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "dev")
)

ROOT = Path(__file__).resolve().parent.parent
SPECS = ROOT / "specs"


@pytest.fixture
def specs_dir() -> Path:
    """The shipped example missions."""
    return SPECS


# Shared test oracles (independent re-implementations) are importable by module name.
sys.path.insert(0, str(Path(__file__).resolve().parent / "oracles"))

from ci_oracles import MISSING_MARK  # noqa: E402


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", f"{MISSING_MARK}(what): the test's oracle is missing in CI (fails the test)"
    )


def pytest_runtest_setup(item: pytest.Item) -> None:
    for mark in item.iter_markers(MISSING_MARK):
        pytest.fail(f"{mark.args[0]} is not installed, and CI must run this oracle", pytrace=False)
