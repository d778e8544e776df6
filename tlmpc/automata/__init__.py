"""Stage 4: LTL → transition-based generalized Büchi automata, with HOA/DOT/JSON formats.

The names below are loaded on first use: the HOA reader and the JSON reader import lark,
which ``tlmpc check`` (translating a task, never reading HOA) does not need.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# imported now: the submodules of the same names would otherwise shadow the functions
from tlmpc.automata.degeneralize import degeneralize
from tlmpc.automata.translate import translate

if TYPE_CHECKING:
    from tlmpc.automata.guards import guard_holds, successor_table
    from tlmpc.automata.hoa import parse_hoa, to_dot, to_hoa
    from tlmpc.automata.io import automaton_from_json, automaton_to_json
    from tlmpc.automata.model import Automaton, Edge

_HOMES = {
    "Automaton": "tlmpc.automata.model",
    "Edge": "tlmpc.automata.model",
    "automaton_from_json": "tlmpc.automata.io",
    "automaton_to_json": "tlmpc.automata.io",
    "guard_holds": "tlmpc.automata.guards",
    "parse_hoa": "tlmpc.automata.hoa",
    "successor_table": "tlmpc.automata.guards",
    "to_dot": "tlmpc.automata.hoa",
    "to_hoa": "tlmpc.automata.hoa",
}


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'tlmpc.automata' has no attribute {name!r}")
    return getattr(importlib.import_module(home), name)


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
