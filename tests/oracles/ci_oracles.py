"""Independent oracles (SPIN, Spot) that a test needs: skipped on a developer's machine that
lacks them, but never in CI (the ``CI`` environment variable set), where a missing oracle fails
the test: a CI run must not pass by silently skipping the checks that give its tests teeth.

SPIN failures (``spin_runner.SpinError``) are failures everywhere, never skips.
"""

from __future__ import annotations

import importlib
import os
from types import ModuleType

import pytest

#: The marker the suite's conftest turns into a failure at set-up.
MISSING_MARK = "oracle_missing"


def in_ci() -> bool:
    """True in a CI run (``CI`` set to anything but empty, ``0`` or ``false``)."""
    return os.environ.get("CI", "").strip().lower() not in ("", "0", "false")


def oracle_required(available: bool, what: str) -> pytest.MarkDecorator:
    """A mark for tests that need ``what``: skip when it is missing, fail instead in CI."""
    if available or not in_ci():
        return pytest.mark.skipif(not available, reason=f"{what} is not installed")
    mark: pytest.MarkDecorator = getattr(pytest.mark, MISSING_MARK)(what)
    return mark


def import_oracle(name: str) -> ModuleType:
    """``import name`` for an oracle: ``pytest.importorskip`` outside CI, a hard import in CI."""
    if in_ci():
        return importlib.import_module(name)
    module: ModuleType = pytest.importorskip(name)
    return module
