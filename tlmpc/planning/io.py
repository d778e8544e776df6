"""``witness.json`` (``tlmpc.witness/1``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from tlmpc.abstraction.model import Abstraction
from tlmpc.planning.model import Witness

FORMAT = "tlmpc.witness/1"


def witness_to_json(witness: Witness, abstraction: Abstraction | None = None) -> dict[str, Any]:
    """The artifact document."""
    del abstraction  # the word already carries the labels
    return {
        "format": FORMAT,
        "prefix": list(witness.prefix),
        "cycle": list(witness.cycle),
        "prefix_states": list(witness.prefix_states),
        "cycle_states": list(witness.cycle_states),
        "word": [list(letter) for letter in witness.word],
        "stay": witness.is_stay,
        "cost": witness.cost,
        "prefix_cost": witness.prefix_cost,
        "cycle_cost": witness.cycle_cost,
        "metric": witness.metric,
        "beta": witness.beta,
        "stats": dict(witness.stats),
        **({"passages": [list(p) for p in witness.passages]} if witness.passages else {}),
    }


def witness_from_json(document: Mapping[str, Any]) -> Witness:
    """Rebuild the :class:`Witness` written by :func:`witness_to_json`."""
    return Witness(
        prefix=tuple(document["prefix"]),
        cycle=tuple(document["cycle"]),
        prefix_states=tuple(document["prefix_states"]),
        cycle_states=tuple(document["cycle_states"]),
        word=tuple(tuple(letter) for letter in document["word"]),
        cost=float(document["cost"]),
        metric=document["metric"],
        beta=float(document["beta"]),
        prefix_cost=float(document["prefix_cost"]),
        cycle_cost=float(document["cycle_cost"]),
        stats=dict(document.get("stats", {})),
        passages=tuple((int(i), int(v)) for i, v in document.get("passages", ())),
    )
