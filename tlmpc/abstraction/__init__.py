"""Stage 3: observation-preserving triangulation and the transition system D."""

from tlmpc.abstraction.build import abstraction_diagnostics, build_abstraction, locate
from tlmpc.abstraction.io import abstraction_from_json, abstraction_to_json
from tlmpc.abstraction.model import Abstraction

__all__ = [
    "Abstraction",
    "abstraction_diagnostics",
    "abstraction_from_json",
    "abstraction_to_json",
    "build_abstraction",
    "locate",
]
