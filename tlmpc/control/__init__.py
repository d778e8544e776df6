"""Stage 6: affine feedback controllers per plan step (vertex second-order-cone programs)."""

from tlmpc.control.io import controllers_from_json, controllers_to_json
from tlmpc.control.model import Controllers, StepController, VelocityJump
from tlmpc.control.synthesize import synthesize

__all__ = [
    "Controllers",
    "StepController",
    "VelocityJump",
    "controllers_from_json",
    "controllers_to_json",
    "synthesize",
]
