"""Parse LTL text into the AST of :mod:`tlmpc.ltl.ast`, keeping source positions.

``parse_ltl(text, file=..., line=..., col=...)`` takes the position where ``text`` starts in
its file (an LTL string inside a YAML mission), so every diagnostic and every node's span
points into the user's file; ``place=`` places every character itself (a YAML string over
several lines, quoted or a block: :mod:`tlmpc.io.scalar_places`).  Problems raise
:class:`~tlmpc.base.errors.InvalidInputError` with L-coded diagnostics; no input, however
malformed, produces a traceback.

Plain formulas are read without lark (:mod:`tlmpc.ltl.reader`, the same AST and spans);
everything else, and every diagnostic, comes from the lark parser
(:mod:`tlmpc.ltl.lark_parser`).
"""

from __future__ import annotations

from tlmpc.ltl.ast import Formula
from tlmpc.ltl.keywords import KEYWORDS  # re-exported: words that cannot name a region
from tlmpc.ltl.places import Place
from tlmpc.ltl.reader import read_plain_ltl

__all__ = ["KEYWORDS", "parse_ltl"]


def parse_ltl(
    text: str,
    *,
    file: str | None = None,
    line: int = 1,
    col: int = 1,
    place: Place | None = None,
) -> Formula:
    """Parse ``text`` (LTL without Next) into an AST.

    Args:
        text: the formula.
        file: the file name to put in diagnostics.
        line: the 1-based line where ``text`` starts in ``file``.
        col: the 1-based column where ``text`` starts in ``file``.
        place: when given, where the character at a 1-based line and column of ``text``
            is written in ``file`` (a YAML string over several lines, quoted or a block);
            ``line`` and ``col`` then only place the whole formula.

    Raises:
        InvalidInputError: with L-coded diagnostics (syntax errors, Next, nesting too deep).
    """
    if isinstance(text, str):
        formula = read_plain_ltl(text, line, col, place)
        if formula is not None:
            return formula
    from tlmpc.ltl.lark_parser import parse_ltl as parse_with_lark

    return parse_with_lark(text, file=file, line=line, col=col, place=place)
