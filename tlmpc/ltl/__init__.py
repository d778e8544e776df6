"""LTL without Next: AST, parser (with positions), printers, rewrites and classes.

The names below are loaded on first use, so that importing the AST (every stage does) does
not import the parser and lark.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from tlmpc.ltl.ast import Formula
    from tlmpc.ltl.keywords import KEYWORDS
    from tlmpc.ltl.parser import parse_ltl
    from tlmpc.ltl.printer import to_spin, to_text
    from tlmpc.ltl.transform import is_cosafe, is_safety, nnf, simplify, substitute

_HOMES = {
    "Formula": "tlmpc.ltl.ast",
    "KEYWORDS": "tlmpc.ltl.keywords",
    "parse_ltl": "tlmpc.ltl.parser",
    "to_spin": "tlmpc.ltl.printer",
    "to_text": "tlmpc.ltl.printer",
    "is_cosafe": "tlmpc.ltl.transform",
    "is_safety": "tlmpc.ltl.transform",
    "nnf": "tlmpc.ltl.transform",
    "simplify": "tlmpc.ltl.transform",
    "substitute": "tlmpc.ltl.transform",
}


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'tlmpc.ltl' has no attribute {name!r}")
    return getattr(importlib.import_module(home), name)


__all__ = [
    "KEYWORDS",
    "Formula",
    "is_cosafe",
    "is_safety",
    "nnf",
    "parse_ltl",
    "simplify",
    "substitute",
    "to_spin",
    "to_text",
]
