"""Stage 7: exact simulation of the closed loop (matrix exponential, root finding)."""

from tlmpc.simulate.exact import Trace, simulate, trace_to_json

__all__ = ["Trace", "simulate", "trace_to_json"]
