"""The runtime executor: compiled plan in, velocity commands out, with recovery.

See docs/python-api.md (the executor) and docs/cli.md (``tlmpc simulate``).
"""

from tlmpc.runtime.closed_loop import ClosedLoopRun, run_closed_loop
from tlmpc.runtime.disturbance import (
    Disturbance,
    DisturbanceModel,
    adversarial_disturbance,
    make_disturbance,
    random_disturbance,
)
from tlmpc.runtime.executor import Executor, RunPlan
from tlmpc.runtime.model import Progress, Recovery
from tlmpc.runtime.unicycle import unicycle_command, unicycle_inflation

__all__ = [
    "ClosedLoopRun",
    "Disturbance",
    "DisturbanceModel",
    "Executor",
    "Progress",
    "Recovery",
    "RunPlan",
    "adversarial_disturbance",
    "make_disturbance",
    "random_disturbance",
    "run_closed_loop",
    "unicycle_command",
    "unicycle_inflation",
]
