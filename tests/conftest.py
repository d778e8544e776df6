"""Shared test configuration.

Hypothesis profiles: ``dev`` (default, thorough) and ``ci`` (smaller example budgets, never
zero), picked by ``HYPOTHESIS_PROFILE`` or, when unset, by the ``CI`` environment variable.
All profiles are derandomized so a failure reproduces on every machine.
"""

from __future__ import annotations

import os
import shutil
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


def spin_path() -> str | None:
    """Path of the SPIN binary, or None when it is not installed."""
    return shutil.which("spin")


requires_spin = pytest.mark.skipif(spin_path() is None, reason="spin is not installed")

# Shared test oracles (independent re-implementations) are importable by module name.
sys.path.insert(0, str(Path(__file__).resolve().parent / "oracles"))
