"""Shared test configuration.

Hypothesis profiles: ``ci`` (the full example budgets, chosen when the ``CI`` environment
variable is set, as ``.ci/run`` sets it) and ``dev`` (the default: a quarter of them, never
zero, so the suite runs in minutes on two cores); ``HYPOTHESIS_PROFILE`` picks one by name.
Tests that set their own budget scale it from ``settings().max_examples``.  All profiles are
derandomized (a failure reproduces on every machine) and have no per-example deadline: no test
result may depend on the machine's speed or load.
"""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

#: The example budget of a property test in CI; the default run uses a quarter of it.
FULL_EXAMPLES = 200

for name, examples in (("ci", FULL_EXAMPLES), ("dev", FULL_EXAMPLES // 4)):
    settings.register_profile(
        name,
        max_examples=examples,
        derandomize=True,
        deadline=None,
        suppress_health_check=[HealthCheck.too_slow],
    )
ROOT = Path(__file__).resolve().parent.parent
SPECS = ROOT / "specs"


@pytest.fixture
def specs_dir() -> Path:
    """The shipped example missions."""
    return SPECS


# Shared test oracles (independent re-implementations) are importable by module name.
sys.path.insert(0, str(Path(__file__).resolve().parent / "oracles"))

from ci_oracles import MISSING_MARK, in_ci  # noqa: E402

settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if in_ci() else "dev"))


def _examples_independent_of_imports() -> None:
    """Hypothesis also draws numbers written in the local modules it finds loaded (tlmpc's
    and the tests'), a set that grows with whatever earlier tests imported: under xdist's
    work stealing one derandomized test drew other examples from one run to the next, and a
    failure seen in the suite did not show when the test ran alone. Its own constants only,
    so a test's examples depend on the test alone (where the internals differ, nothing is
    changed)."""
    try:
        from hypothesis.internal.conjecture import providers
    except ImportError:  # pragma: no cover - a Hypothesis without the module
        return
    empty = getattr(providers, "_local_constants", None)
    if empty is None or not callable(getattr(providers, "_get_local_constants", None)):
        return
    providers._get_local_constants = lambda: empty


_examples_independent_of_imports()


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", f"{MISSING_MARK}(what): the test's oracle is missing in CI (fails the test)"
    )
    # A suite started in the background (`cmd &` in a script) inherits Ctrl-C ignored, and so
    # would every command the tests start (tlmpc keeps a signal ignored by whoever started
    # it): the tests of Ctrl-C model a user at a terminal.  A handler does not survive exec,
    # so the commands start with the default disposition again.
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_runtest_setup(item: pytest.Item) -> None:
    for mark in item.iter_markers(MISSING_MARK):
        pytest.fail(f"{mark.args[0]} is not installed, and CI must run this oracle", pytrace=False)
