"""LTL without Next: AST, parser (with positions), printers, rewrites and classes."""

from tlmpc.ltl.ast import Formula
from tlmpc.ltl.parser import KEYWORDS, parse_ltl
from tlmpc.ltl.printer import to_spin, to_text
from tlmpc.ltl.transform import is_cosafe, is_safety, nnf, simplify, substitute

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
