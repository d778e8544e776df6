"""Stage 7: exact simulation of the closed loop (matrix exponential, root finding)."""

from tlmpc.simulate.exact import Trace, simulate, trace_to_json
from tlmpc.simulate.io import trace_from_json

__all__ = ["Trace", "simulate", "trace_from_json", "trace_to_json"]
