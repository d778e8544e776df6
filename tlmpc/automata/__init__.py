"""Stage 4: LTL → transition-based generalized Büchi automata, with HOA/DOT/JSON formats."""

from tlmpc.automata.degeneralize import degeneralize
from tlmpc.automata.guards import guard_holds, successor_table
from tlmpc.automata.hoa import parse_hoa, to_dot, to_hoa
from tlmpc.automata.io import automaton_from_json, automaton_to_json
from tlmpc.automata.model import Automaton, Edge
from tlmpc.automata.translate import translate

__all__ = [
    "Automaton",
    "Edge",
    "automaton_from_json",
    "automaton_to_json",
    "degeneralize",
    "guard_holds",
    "parse_hoa",
    "successor_table",
    "to_dot",
    "to_hoa",
    "translate",
]
