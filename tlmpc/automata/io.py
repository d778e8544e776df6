"""``automaton.json`` (``tlmpc.automaton/1``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from tlmpc.automata.model import Automaton, Edge
from tlmpc.ltl.printer import to_text

FORMAT = "tlmpc.automaton/1"


def automaton_to_json(automaton: Automaton) -> dict[str, Any]:
    """The artifact document: states, edges (guards as LTL text), acceptance."""
    document: dict[str, Any] = {
        "format": FORMAT,
        "formula": automaton.formula,
        "aps": list(automaton.aps),
        "states": [
            {"id": i, "name": automaton.state_names[i] if i < len(automaton.state_names) else ""}
            for i in range(automaton.num_states)
        ],
        "initial": automaton.initial,
        "acceptance": {
            "kind": "buchi" if automaton.state_based else "generalized-buchi",
            "sets": automaton.num_acc,
            "state_based": automaton.state_based,
        },
        "edges": [
            {"src": e.src, "dst": e.dst, "guard": to_text(e.guard), "marks": sorted(e.marks)}
            for e in automaton.edges
        ],
    }
    if automaton.letters is not None:
        document["letters"] = [list(letter) for letter in automaton.letters]
    return document


def automaton_from_json(document: Mapping[str, Any]) -> Automaton:
    """Rebuild the automaton written by :func:`automaton_to_json`."""
    from tlmpc.ltl.parser import parse_ltl  # lark: only when reading an automaton back

    acceptance = document["acceptance"]
    return Automaton(
        aps=tuple(document["aps"]),
        num_states=len(document["states"]),
        initial=int(document["initial"]),
        edges=tuple(
            Edge(
                src=e["src"], dst=e["dst"], guard=parse_ltl(e["guard"]), marks=frozenset(e["marks"])
            )
            for e in document["edges"]
        ),
        num_acc=int(acceptance["sets"]),
        state_names=tuple(s["name"] for s in document["states"]),
        formula=str(document.get("formula", "")),
        state_based=bool(acceptance.get("state_based", False)),
        letters=(
            None
            if document.get("letters") is None
            else tuple(tuple(str(x) for x in letter) for letter in document["letters"])
        ),
    )
