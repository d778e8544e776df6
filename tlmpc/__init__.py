"""tlmpc: a temporal logic motion planning compiler and verifier.

The method is Fainekos, Kress-Gazit and Pappas, "Temporal Logic Motion Planning for Mobile
Robots" (ICRA 2005): triangulate the workspace, plan on the transition system with an LTL
automaton, realise the plan with affine feedback per triangle, and check the trajectory.

The Python facade (see ``docs/python-api.md``)::

    import tlmpc
    result = tlmpc.compile("specs/example1.yaml")    # a path, YAML text or a dict
    tlmpc.verify_trace(result).satisfied
"""

from __future__ import annotations

# first: a Ctrl-C or SIGTERM while the command is still importing ends it cleanly (the
# guard does nothing when tlmpc is imported as a library)
from tlmpc.base.startup import guard_start as _guard_start

_guard_start()

from typing import TYPE_CHECKING, Any  # noqa: E402

from tlmpc.base.errors import (  # noqa: E402
    Diagnostic,
    InvalidInputError,
    NoPlanError,
    SolverError,
    TlmpcError,
    UsageError,
)
from tlmpc.base.version import __version__  # noqa: E402

if TYPE_CHECKING:
    from tlmpc.api import (
        Compiled,
        check,
        compile,
        executor,
        reactive_executor,
        read_output,
        translate,
        verify_trace,
    )

_FACADE = frozenset(
    {
        "Compiled",
        "check",
        "compile",
        "executor",
        "reactive_executor",
        "read_output",
        "translate",
        "verify_trace",
    }
)


def __getattr__(name: str) -> Any:
    # the facade is loaded on first use: the command line does not need it to start
    if name in _FACADE:
        from tlmpc import api

        return getattr(api, name)
    raise AttributeError(f"module 'tlmpc' has no attribute {name!r}")


__all__ = [
    "Compiled",
    "Diagnostic",
    "InvalidInputError",
    "NoPlanError",
    "SolverError",
    "TlmpcError",
    "UsageError",
    "__version__",
    "check",
    "compile",
    "executor",
    "reactive_executor",
    "read_output",
    "translate",
    "verify_trace",
]
