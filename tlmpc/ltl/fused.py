"""Propositions that look like operators written together with a name (``GFa`` for ``G F a``).

In tlmpc's grammar, as in Spot's, ``GFa`` is one proposition named ``GFa``: operators are
words of their own.  People used to papers that write ``GFa`` for "infinitely often a" get an
unknown-region error; the hint names the formula they probably meant.
"""

from __future__ import annotations

from collections.abc import Collection

#: The unary temporal operators of the grammar (X has no place in it: the semantics is
#: stutter-invariant), the letters that fuse with a following name.
UNARY_OPERATORS = frozenset("FG")


def fused_operators(name: str, known: Collection[str]) -> str | None:
    """``"G F a"`` when ``name`` is unary operators fused with a known name (``GFa``),
    else None (``name`` itself known, or what follows the operators is not a known name)."""
    if name in known:
        return None
    split = 0
    while split < len(name) - 1 and name[split] in UNARY_OPERATORS:
        split += 1
        if name[split:] in known:
            return " ".join(name[:split]) + " " + name[split:]
    return None
