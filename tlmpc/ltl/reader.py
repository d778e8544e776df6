"""A lark-free reader for well-formed LTL formulas: the same AST and spans as the parser.

Importing lark (and ``regex``, which lark pulls in) costs a cold compile tens of
milliseconds, for formulas that are almost always plain: region names, the operators and
parentheses.  This recursive-descent reader covers exactly that part of the grammar in
``ltl.lark`` and answers only when it is sure; for anything else — a quoted name, an
operator keyword where a name should stand, Next, a syntax error, deep nesting — it answers
None and :mod:`tlmpc.ltl.lark_parser` parses the text (and words the diagnostics).

Spans follow lark's position propagation: a leaf spans its token; any other node runs from
the start of its first part to the end of its last, where a parenthesised part counts with
its outermost parentheses (the node inside keeps its own span).  A test compares this reader
with the lark parser on drawn formulas.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import NamedTuple

from tlmpc.ltl.ast import (
    And,
    Const,
    Equiv,
    Eventually,
    Formula,
    Globally,
    Implies,
    Not,
    Or,
    Prop,
    Release,
    Span,
    StrongRelease,
    Until,
    WeakUntil,
)
from tlmpc.ltl.keywords import KEYWORDS
from tlmpc.ltl.places import Place, placed

#: Formulas nested deeper than this are left to the lark parser (which refuses > 400 with
#: L005); far below Python's recursion limit at a handful of frames per level.
MAX_READ_DEPTH = 40
#: Longer formulas are left to the lark parser as well.
MAX_READ_TOKENS = 4000

#: Punctuation operators, longest spelling first (as lark's lexer tries them).
_PUNCTUATION = (
    ("<->", "EQUIV"),
    ("<=>", "EQUIV"),
    ("->", "IMPLIES"),
    ("=>", "IMPLIES"),
    ("||", "OR"),
    ("\\/", "OR"),
    ("&&", "AND"),
    ("/\\", "AND"),
    ("<>", "EVENTUALLY"),
    ("[]", "ALWAYS"),
    ("|", "OR"),
    ("&", "AND"),
    ("!", "NOT"),
    ("~", "NOT"),
    ("(", "LPAR"),
    (")", "RPAR"),
)
_WORD = re.compile(r"[A-Za-z0-9_]+")
_SPACE = " \t\f\r\n"  # lark's common.WS
_CHAIN = re.compile(r"[FG]+")
_BINARY: dict[str, Callable[..., Formula]] = {
    "U": Until,
    "R": Release,
    "V": Release,
    "W": WeakUntil,
    "M": StrongRelease,
}
#: Words the lark grammar reads as something else than a name (constants, operators, Next).
_SPECIAL = re.compile(r"[FGXN]+|[URWMV]|true|false|[0-9].*")


class _Token(NamedTuple):
    kind: str
    text: str
    start: tuple[int, int]  # 1-based line and column, relative to the text
    end: tuple[int, int]  # the column after the last character


class _Part(NamedTuple):
    formula: Formula
    start: tuple[int, int]  # with the outermost parentheses around it, if any
    end: tuple[int, int]


class _Unsure(Exception):
    """The text is outside what this reader decides: the lark parser takes it."""


def _tokens(text: str) -> list[_Token]:
    found: list[_Token] = []
    line, line_start, index = 1, 0, 0
    length = len(text)
    while index < length:
        char = text[index]
        if char in _SPACE:
            if char == "\n":
                line, line_start = line + 1, index + 1
            index += 1
            continue
        column = index - line_start + 1
        word = _WORD.match(text, index)
        if word is not None:
            spelled, kind = word.group(), "WORD"
        else:
            punctuation = next((p for p in _PUNCTUATION if text.startswith(p[0], index)), None)
            if punctuation is None:
                raise _Unsure  # a quoted name, or a character the grammar does not know
            spelled, kind = punctuation
        found.append(_Token(kind, spelled, (line, column), (line, column + len(spelled))))
        index += len(spelled)
        if len(found) > MAX_READ_TOKENS:
            raise _Unsure
    return found


class _Reader:
    def __init__(self, tokens: list[_Token], shift: Callable[[tuple[int, int]], tuple[int, int]]):
        self.tokens = tokens
        self.index = 0
        self.shift = shift
        self.depth = 0

    def _span(self, start: tuple[int, int], end: tuple[int, int]) -> Span:
        first, last = self.shift(start), self.shift(end)
        return Span(first[0], first[1], last[0], last[1])

    def _peek(self) -> _Token | None:
        return self.tokens[self.index] if self.index < len(self.tokens) else None

    def _take(self) -> _Token:
        token = self._peek()
        if token is None:
            raise _Unsure  # ends too early
        self.index += 1
        return token

    def _nested(self) -> None:
        self.depth += 1
        if self.depth > MAX_READ_DEPTH:
            raise _Unsure

    def formula(self) -> Formula:
        part = self._implies()
        if self._peek() is not None:
            raise _Unsure  # something left over
        return part.formula

    def _implies(self) -> _Part:
        left = self._disjunction()
        token = self._peek()
        if token is None or token.kind not in ("IMPLIES", "EQUIV"):
            return left
        self._take()
        self._nested()
        right = self._implies()
        self.depth -= 1
        build = Implies if token.kind == "IMPLIES" else Equiv
        return _Part(
            build(left.formula, right.formula, span=self._span(left.start, right.end)),
            left.start,
            right.end,
        )

    def _disjunction(self) -> _Part:
        return self._chain("OR", self._conjunction, Or)

    def _conjunction(self) -> _Part:
        return self._chain("AND", self._temporal, And)

    def _chain(
        self, kind: str, operand: Callable[[], _Part], build: Callable[..., Formula]
    ) -> _Part:
        parts = [operand()]
        while (token := self._peek()) is not None and token.kind == kind:
            self._take()
            parts.append(operand())
        if len(parts) == 1:
            return parts[0]
        start, end = parts[0].start, parts[-1].end
        formula = build(tuple(p.formula for p in parts), span=self._span(start, end))
        return _Part(formula, start, end)

    def _temporal(self) -> _Part:
        left = self._unary()
        token = self._peek()
        if token is None or token.kind != "WORD" or token.text not in _BINARY:
            return left
        self._take()
        self._nested()
        right = self._temporal()
        self.depth -= 1
        formula = _BINARY[token.text](
            left.formula, right.formula, span=self._span(left.start, right.end)
        )
        return _Part(formula, left.start, right.end)

    def _unary(self) -> _Part:
        token = self._take()
        if token.kind == "NOT":
            operators = "!"
        elif token.kind == "EVENTUALLY":
            operators = "F"
        elif token.kind == "ALWAYS":
            operators = "G"
        elif token.kind == "WORD" and _CHAIN.fullmatch(token.text):
            operators = token.text
        else:
            return self._atom(token)
        self.depth += len(operators)  # `FGFG a` is one token but four levels
        if self.depth > MAX_READ_DEPTH:
            raise _Unsure
        operand = self._unary()
        self.depth -= len(operators)
        formula = operand.formula
        for index in range(len(operators) - 1, -1, -1):
            # each letter of a chain (`GF`, one token) spans its own subformula
            symbol = operators[index]
            span = self._span((token.start[0], token.start[1] + index), operand.end)
            if symbol == "!":
                formula = Not(formula, span=span)
            elif symbol == "F":
                formula = Eventually(formula, span=span)
            else:
                formula = Globally(formula, span=span)
        return _Part(formula, token.start, operand.end)

    def _atom(self, token: _Token) -> _Part:
        if token.kind == "LPAR":
            self._nested()
            inner = self._implies()
            self.depth -= 1
            closing = self._take()
            if closing.kind != "RPAR":
                raise _Unsure
            return _Part(inner.formula, token.start, closing.end)
        if token.kind != "WORD":
            raise _Unsure
        span = self._span(token.start, token.end)
        if token.text == "true" or token.text == "1":
            return _Part(Const(True, span=span), token.start, token.end)
        if token.text == "false" or token.text == "0":
            return _Part(Const(False, span=span), token.start, token.end)
        if token.text in KEYWORDS or _SPECIAL.fullmatch(token.text):
            raise _Unsure  # an operator where a name should stand, Next, a number
        return _Part(Prop(token.text, span=span), token.start, token.end)


def read_plain_ltl(
    text: str,
    line: int = 1,
    col: int = 1,
    place: Place | None = None,
) -> Formula | None:
    """The formula of ``text`` (starting at ``line``:``col`` of its file, or with each
    character where ``place`` says) when it is plain LTL this reader decides; None to leave
    it to the lark parser."""

    def shift(position: tuple[int, int]) -> tuple[int, int]:
        return placed(*position, (line, col), place)

    try:
        tokens = _tokens(text)
        if not tokens:
            return None
        return _Reader(tokens, shift).formula()
    except (_Unsure, RecursionError):
        return None
