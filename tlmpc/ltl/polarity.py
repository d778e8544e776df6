"""The polarity of each proposition in a formula: goals occur positively, avoided regions
negatively (in the negation normal form).

A formula is monotone in a proposition of one polarity: growing the set where a positive one
holds (or shrinking it for a negative one) never falsifies it.  The planner uses this to plan
with goals shrunk to their cores and avoided regions grown by a margin, and the clearance
report to know which regions are goals and which are to be kept away from.
"""

from __future__ import annotations

from typing import Literal

from tlmpc.ltl.ast import Formula, Not, Prop
from tlmpc.ltl.transform import nnf

Polarity = Literal["positive", "negative", "both"]


def polarities(formula: Formula) -> dict[str, Polarity]:
    """Each proposition's polarity in the negation normal form of ``formula``."""
    found: dict[str, set[bool]] = {}
    stack: list[tuple[Formula, bool]] = [(nnf(formula), True)]
    while stack:
        node, positive = stack.pop()
        if isinstance(node, Prop):
            found.setdefault(node.name, set()).add(positive)
        elif isinstance(node, Not):
            stack.append((node.arg, not positive))
        else:
            stack.extend((child, positive) for child in node.children())
    return {
        name: "both" if len(signs) == 2 else ("positive" if True in signs else "negative")
        for name, signs in found.items()
    }
