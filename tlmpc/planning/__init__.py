"""Stage 5: product of D and the automaton, minimum-cost lasso, no-plan explanations."""

from tlmpc.planning.io import witness_from_json, witness_to_json
from tlmpc.planning.model import Witness
from tlmpc.planning.plan import plan

__all__ = ["Witness", "plan", "witness_from_json", "witness_to_json"]
