"""tlmpc: a temporal logic motion planning compiler and verifier.

The method is Fainekos, Kress-Gazit and Pappas, "Temporal Logic Motion Planning for Mobile
Robots" (ICRA 2005): triangulate the workspace, plan on the transition system with an LTL
automaton, realise the plan with affine feedback per triangle, and check the trajectory.

The Python facade (see ``docs/python-api.md``)::

    import tlmpc
    result = tlmpc.compile("specs/example1.yaml")    # a path, YAML text or a dict
    tlmpc.verify_trace(result).satisfied
"""

__version__ = "0.1.0"

from tlmpc.api import (
    Compiled,
    check,
    compile,
    executor,
    read_output,
    translate,
    verify_trace,
)
from tlmpc.errors import (
    Diagnostic,
    InvalidInputError,
    NoPlanError,
    SolverError,
    TlmpcError,
    UsageError,
)

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
    "read_output",
    "translate",
    "verify_trace",
]
