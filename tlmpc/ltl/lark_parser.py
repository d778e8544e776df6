"""Parse LTL text with lark into the AST of :mod:`tlmpc.ltl.ast`, keeping source positions.

The reference parser and the one that words every syntax error; :mod:`tlmpc.ltl.parser`
tries a lark-free reader first (see :mod:`tlmpc.ltl.reader`).

``parse_ltl(text, file=..., line=..., col=...)`` takes the position where ``text`` starts in
its file (an LTL string inside a YAML mission), so every diagnostic and every node's span
points into the user's file; ``place=`` places every character itself (a YAML string over
several lines, quoted or a block: :mod:`tlmpc.io.scalar_places`).  Problems raise
:class:`~tlmpc.base.errors.InvalidInputError` with L-coded diagnostics; no input, however
malformed, produces a traceback.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable
from importlib import resources
from typing import Any

from lark import Lark, Token, Transformer, Tree, v_args
from lark.exceptions import (
    LarkError,
    UnexpectedCharacters,
    UnexpectedEOF,
    UnexpectedToken,
    VisitError,
)

from tlmpc.base.depth import NESTING_LIMIT
from tlmpc.base.errors import Diagnostic, InvalidInputError, error
from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedGlobally,
    BoundedUntil,
    Const,
    Equiv,
    Eventually,
    Formula,
    Globally,
    Implies,
    Interval,
    Not,
    Or,
    Prop,
    Release,
    Span,
    StrongRelease,
    Until,
    WeakUntil,
)
from tlmpc.ltl.grammar_cache import lalr_parser
from tlmpc.ltl.keywords import KEYWORDS  # re-exported: words that cannot name a region
from tlmpc.ltl.places import Place, placed

#: Nesting deeper than this is refused (L005) instead of exhausting the Python stack.
MAX_DEPTH = NESTING_LIMIT

_NEXT_HINT = (
    "Next (X) has no meaning in continuous time: a robot has no 'next instant'. tlmpc keeps "
    "formulas stutter-invariant, which is what makes the discrete plan sound for the "
    "continuous robot; say what must happen eventually (F) or until something (U) instead"
)

_BINARY_TEMPORAL: dict[str, Callable[..., Formula]] = {
    "U": Until,
    "R": Release,
    "V": Release,
    "W": WeakUntil,
    "M": StrongRelease,
}


_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_INFINITY = re.compile(r"([+-]?)(?:inf|infinity|∞)", re.IGNORECASE)
_NOT_A_NUMBER = re.compile(r"[+-]?nan", re.IGNORECASE)
_INTERVAL_HINT = "write a closed interval of seconds [a,b] with 0 <= a <= b, e.g. F[0,30] dock"


def _interval_problem(text: str) -> tuple[str, str, Interval | None]:
    """``(code, message, interval)``: the interval of ``[a,b]`` text, or why it is none."""
    body = text[1:-1]
    text = " ".join(text.split())  # as shown: a bound written over lines on one line
    parts = body.split(",")
    if len(parts) != 2:
        return "L040", f"the time bound {text} needs exactly two bounds [a,b]", None
    bounds: list[float] = []
    for part in (p.strip() for p in parts):
        if _NUMBER.fullmatch(part):
            value = float(part)
            if math.isinf(value):
                # written finite, read unbounded: the window would change its meaning
                return (
                    "L040",
                    f"the time bound {text}: {part} is too large for a float"
                    " (inf is a window without end)",
                    None,
                )
            bounds.append(value)
        elif infinity := _INFINITY.fullmatch(part):
            bounds.append(-math.inf if infinity.group(1) == "-" else math.inf)
        elif _NOT_A_NUMBER.fullmatch(part):
            return "L043", f"the time bound {text} is not a number (NaN)", None
        else:
            return "L040", f"the time bound {text}: {part!r} is not a number of seconds", None
    low, high = bounds
    if low < 0 or high < 0:
        return "L042", f"the time bound {text} is negative: bounds look into the future", None
    if math.isinf(low):
        return "L043", f"the time bound {text} starts at infinity: no instant is in it", None
    if low > high:
        low_text, high_text = parts[0].strip(), parts[1].strip()
        return "L041", f"the time bound {text} is empty: {low_text} > {high_text}", None
    return "", "", Interval(low, high)


@functools.cache
def _parser() -> Lark:
    grammar = (resources.files("tlmpc.ltl") / "ltl.lark").read_text(encoding="utf-8")
    parser: Lark = lalr_parser(grammar, propagate_positions=True, maybe_placeholders=False)
    return parser


class _Positions:
    """Shifts lark's 1-based positions (relative to the text) into the user's file."""

    def __init__(self, line: int, col: int, place: Place | None = None) -> None:
        self.line = line
        self.col = col
        self.place = place

    def at(self, line: int, col: int) -> tuple[int, int]:
        return placed(line, col, (self.line, self.col), self.place)

    def span(self, line: int, col: int, end_line: int, end_col: int) -> Span:
        start = self.at(line, col)
        end = self.at(end_line, end_col)
        return Span(start[0], start[1], end[0], end[1])


def _token_span(pos: _Positions, token: Token) -> Span:
    return pos.span(
        token.line or 1,
        token.column or 1,
        token.end_line or token.line or 1,
        token.end_column or (token.column or 1) + len(token),
    )


#: An escape inside a quoted name other than ``\\"``, ``\\\\`` and ``\\n`` (group 1: the escape).
_UNKNOWN_ESCAPE = re.compile(r'(?:^|[^\\])(?:\\\\)*(\\[^"\\n])')


def unquote(token: str) -> str:
    """The name inside a quoted proposition: ``\\n`` is a newline, ``\\"`` a quote and
    ``\\\\`` a backslash (any other escape is refused by the parser, L031)."""
    body = token[1:-1]
    if "\\" not in body:
        return body
    out = []
    chars = iter(body)
    for char in chars:
        if char == "\\":
            escaped = next(chars, "")
            out.append("\n" if escaped == "n" else escaped)
        else:
            out.append(char)
    return "".join(out)


class _ToAst(Transformer[Token, Formula]):
    def __init__(self, pos: _Positions, file: str | None) -> None:
        super().__init__()
        self.pos = pos
        self.file = file
        #: Operator keywords used as bare proposition names (L030), unknown escapes in quoted
        #: names (L031) and bad time bounds (L040-L044), reported after the walk.
        self.problems: list[Diagnostic] = []

    def _span(self, meta: Any) -> Span | None:
        if getattr(meta, "empty", True):
            return None
        return self.pos.span(meta.line, meta.column, meta.end_line, meta.end_column)

    @v_args(meta=True)
    def true_const(self, meta: Any, children: list[Token]) -> Formula:
        return Const(True, span=_token_span(self.pos, children[0]))

    @v_args(meta=True)
    def false_const(self, meta: Any, children: list[Token]) -> Formula:
        return Const(False, span=_token_span(self.pos, children[0]))

    @v_args(meta=True)
    def prop(self, meta: Any, children: list[Token]) -> Formula:
        name = str(children[0])
        span = _token_span(self.pos, children[0])
        if name in KEYWORDS:
            # The contextual lexer reads `U` as a name where no operator can stand (`U U U`).
            self.problems.append(
                error(
                    "L030",
                    f"{name!r} is an operator of the language, not a proposition name",
                    hint=f'an operator cannot stand here; write "{name}" in double quotes for '
                    f"a proposition named {name} (a mission cannot name a region after an "
                    "operator)",
                    file=self.file,
                    line=span.line,
                    col=span.col,
                )
            )
        return Prop(name, span=span)

    @v_args(meta=True)
    def quoted_prop(self, meta: Any, children: list[Token]) -> Formula:
        token = children[0]
        span = _token_span(self.pos, token)
        unknown = _UNKNOWN_ESCAPE.search(str(token))
        if unknown is not None:
            # `"a\tb"` read as `atb` would name another region than the one meant
            line, col = self.pos.at(token.line or 1, (token.column or 1) + unknown.start(1))
            self.problems.append(
                error(
                    "L031",
                    f"unknown escape `{unknown.group(1)}` in the quoted name {token!s}",
                    hint='inside quotes \\" is a quote, \\\\ a backslash and \\n a newline',
                    file=self.file,
                    line=line,
                    col=col,
                )
            )
        return Prop(unquote(str(token)), span=span)

    @v_args(meta=True)
    def not_op(self, meta: Any, children: list[Any]) -> Formula:
        return Not(children[1], span=self._span(meta))

    def _letter_span(self, meta: Any, chain: Token, index: int) -> Span | None:
        """From the ``index``-th letter of an operator chain (``GF``: one token) to the end of
        the formula it applies to: each letter's own subformula."""
        if getattr(meta, "empty", True):
            return None
        column = (chain.column or meta.column) + index
        return self.pos.span(chain.line or meta.line, column, meta.end_line, meta.end_column)

    @v_args(meta=True)
    def unary_op(self, meta: Any, children: list[Any]) -> Formula:
        token, operand = children[0], children[1]
        operators = str(token)
        if operators in ("<>", "[]"):
            # one operator of two characters: its span starts at the first
            operators = "F" if operators == "<>" else "G"
        result: Formula = operand
        for index in range(len(operators) - 1, -1, -1):
            # X/N were rejected before the transformation; only F and G reach here.
            span = self._letter_span(meta, token, index)
            result = (
                Eventually(result, span=span)
                if operators[index] == "F"
                else Globally(result, span=span)
            )
        return result

    def _interval(self, token: Token) -> Interval:
        code, message, interval = _interval_problem(str(token))
        if interval is not None:
            return interval
        span = _token_span(self.pos, token)
        self.problems.append(
            error(code, message, hint=_INTERVAL_HINT, file=self.file, line=span.line, col=span.col)
        )
        return Interval(0.0, 0.0)  # a placeholder: the parse fails with the diagnostic

    @v_args(meta=True)
    def bounded_unary_op(self, meta: Any, children: list[Any]) -> Formula:
        letters, token, operand = children[0], children[1], children[2]
        chain = str(letters)
        interval = self._interval(token)
        # The bound belongs to the last letter of a chain: `GF[0,10] a` is `G F[0,10] a`.
        last = self._letter_span(meta, letters, len(chain) - 1)
        result: Formula = (
            BoundedEventually(operand, interval, span=last)
            if chain[-1] == "F"
            else BoundedGlobally(operand, interval, span=last)
        )
        for index in range(len(chain) - 2, -1, -1):
            span = self._letter_span(meta, letters, index)
            result = (
                Eventually(result, span=span)
                if chain[index] == "F"
                else Globally(result, span=span)
            )
        return result

    @v_args(meta=True)
    def bounded_temporal_op(self, meta: Any, children: list[Any]) -> Formula:
        left, op, token, right = children
        interval = self._interval(token)
        if str(op) != "U":
            span = _token_span(self.pos, op)
            self.problems.append(
                error(
                    "L044",
                    f"only U takes a time bound, not {op}",
                    hint="bounded operators are F[a,b], G[a,b] and U[a,b]; write "
                    "`a R[a,b] b` as `!(!a U[a,b] !b)`",
                    file=self.file,
                    line=span.line,
                    col=span.col,
                )
            )
        return BoundedUntil(left, right, interval, span=self._span(meta))

    @v_args(meta=True)
    def temporal_op(self, meta: Any, children: list[Any]) -> Formula:
        left, op, right = children
        return _BINARY_TEMPORAL[str(op)](left, right, span=self._span(meta))

    @v_args(meta=True)
    def and_op(self, meta: Any, children: list[Any]) -> Formula:
        return And(tuple(c for c in children if not isinstance(c, Token)), span=self._span(meta))

    @v_args(meta=True)
    def or_op(self, meta: Any, children: list[Any]) -> Formula:
        return Or(tuple(c for c in children if not isinstance(c, Token)), span=self._span(meta))

    @v_args(meta=True)
    def implies_op(self, meta: Any, children: list[Any]) -> Formula:
        return Implies(children[0], children[2], span=self._span(meta))

    @v_args(meta=True)
    def equiv_op(self, meta: Any, children: list[Any]) -> Formula:
        return Equiv(children[0], children[2], span=self._span(meta))


_EXPECTED_NAMES = {
    "NAME": "a region name",
    "STRING": "a quoted name",
    "TRUE": "true",
    "FALSE": "false",
    "LPAR": "'('",
    "RPAR": "')'",
    "NOT": "'!'",
    "UNARY_CHAIN": "F or G",
    "EVENTUALLY": "'<>'",
    "ALWAYS": "'[]'",
    "AND": "'&'",
    "OR": "'|'",
    "IMPLIES": "'->'",
    "EQUIV": "'<->'",
    "BINTEMP": "U, R, W or M",
    "INTERVAL": "a time bound [a,b]",
    "$END": "the end of the formula",
}


_OPERAND_STARTS = frozenset(
    {"NAME", "STRING", "TRUE", "FALSE", "LPAR", "NOT", "UNARY_CHAIN", "EVENTUALLY", "ALWAYS"}
)
_OPERAND = "an operand (a region name, true, false, '(' or one of ! F G [] <>)"


def _describe_expected(expected: set[str] | frozenset[str], open_parens: int = 1) -> str:
    expected = set(expected)
    if open_parens <= 0:
        # LALR merges lookaheads, so ')' shows up even where no '(' is open.
        expected.discard("RPAR")
    parts: list[str] = []
    if expected & _OPERAND_STARTS:
        parts.append(_OPERAND)
        expected -= _OPERAND_STARTS
    if expected & {"AND", "OR", "IMPLIES", "EQUIV", "BINTEMP"} == {
        "AND",
        "OR",
        "IMPLIES",
        "EQUIV",
        "BINTEMP",
    }:
        parts.append("a binary operator (& | -> <-> U R W M)")
        expected -= {"AND", "OR", "IMPLIES", "EQUIV", "BINTEMP"}
    parts.extend(sorted(_EXPECTED_NAMES.get(e, e) for e in expected))
    if not parts:
        return "something else"
    return ", ".join(parts[:-1]) + (" or " if len(parts) > 1 else "") + parts[-1]


def _open_parens(text: str, end: int) -> int:
    return text[:end].count("(") - text[:end].count(")")


def _tree_depth(tree: Tree[Token]) -> int:
    deepest = 0
    stack: list[tuple[Tree[Token], int]] = [(tree, 1)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        # `FGFG a` is one token but as many AST levels as letters.
        step = sum(
            len(c) for c in node.children if isinstance(c, Token) and c.type == "UNARY_CHAIN"
        )
        stack.extend((c, depth + max(step, 1)) for c in node.children if isinstance(c, Tree))
    return deepest


def _max_depth(text: str) -> int:
    """The deepest nesting of brackets in ``text``, outside double-quoted names (a name may
    hold any character, brackets too)."""
    depth = deepest = 0
    quoted = escaped = False
    for char in text:
        if quoted:
            if escaped:
                escaped = False
            elif char == "\\":
                escaped = True
            elif char == '"':
                quoted = False
            continue
        if char == '"':
            quoted = True
        elif char == "(":
            depth += 1
            deepest = max(deepest, depth)
        elif char == ")":
            depth -= 1
    return deepest


def _syntax_diagnostic(exc: LarkError, text: str, file: str | None, pos: _Positions) -> Diagnostic:
    if isinstance(exc, UnexpectedCharacters):
        line, col = pos.at(exc.line, exc.column)
        index = exc.pos_in_stream if exc.pos_in_stream is not None else -1
        char = text[index] if 0 <= index < len(text) else "?"
        return error(
            "L001",
            f"unexpected character {char!r} in LTL formula",
            hint="operators are ! & | -> <-> U R W M F G (or [] <> && || ~); "
            "names are letters, digits and _",
            file=file,
            line=line,
            col=col,
        )
    if isinstance(exc, UnexpectedToken):
        token = exc.token
        if token.type == "$END":
            line, col = pos.at(*_end_position(text))
            return error(
                "L002",
                "the LTL formula ends too early",
                hint=f"expected {_describe_expected(exc.expected, _open_parens(text, len(text)))}",
                file=file,
                line=line,
                col=col,
            )
        line, col = pos.at(token.line or 1, token.column or 1)
        return error(
            "L003",
            f"unexpected {str(token)!r} in LTL formula",
            hint="expected "
            + _describe_expected(exc.expected, _open_parens(text, token.start_pos or 0))
            + " here",
            file=file,
            line=line,
            col=col,
        )
    if isinstance(exc, UnexpectedEOF):
        line, col = pos.at(*_end_position(text))
        return error(
            "L002",
            "the LTL formula ends too early",
            hint="complete the formula (an operand or a closing ')' is missing)",
            file=file,
            line=line,
            col=col,
        )
    return error("L003", f"cannot parse LTL formula: {exc}", file=file, line=pos.line, col=pos.col)


def _end_position(text: str) -> tuple[int, int]:
    lines = text.split("\n")
    return len(lines), len(lines[-1]) + 1


def _next_operators(tokens: list[Token], pos: _Positions, file: str | None) -> list[Diagnostic]:
    found = []
    for token in tokens:
        if token.type == "UNARY_CHAIN" and ("X" in token or "N" in token):
            line, col = pos.at(
                token.line or 1, (token.column or 1) + str(token).find("X" if "X" in token else "N")
            )
            found.append(
                error(
                    "L004",
                    "the Next operator (X) is not allowed",
                    hint=_NEXT_HINT,
                    file=file,
                    line=line,
                    col=col,
                )
            )
    return found


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
            is written in ``file`` (``line``/``col`` then only place the whole formula).

    Raises:
        InvalidInputError: with L-coded diagnostics (syntax errors, Next, nesting too deep).
    """
    pos = _Positions(line, col, place)
    if not isinstance(text, str):
        raise InvalidInputError(
            error("L003", "an LTL formula must be a string", file=file, line=line, col=col)
        )
    if not text.strip():
        raise InvalidInputError(
            error(
                "L002",
                "the LTL formula is empty",
                hint="write a formula such as `F goal`",
                file=file,
                line=line,
                col=col,
            )
        )
    if _max_depth(text) > MAX_DEPTH:
        raise InvalidInputError(
            error(
                "L005",
                f"the LTL formula is nested more than {MAX_DEPTH} levels deep",
                hint="split the task into several phrases or conjuncts",
                file=file,
                line=line,
                col=col,
            )
        )
    parser = _parser()
    try:
        tokens = list(parser.lex(text))
    except LarkError as exc:
        raise InvalidInputError(_syntax_diagnostic(exc, text, file, pos)) from None
    next_diagnostics = _next_operators(tokens, pos, file)
    if next_diagnostics:
        raise InvalidInputError(next_diagnostics)
    try:
        tree = parser.parse(text)
    except LarkError as exc:
        raise InvalidInputError(_syntax_diagnostic(exc, text, file, pos)) from None
    too_deep = error(
        "L005",
        f"the LTL formula is nested more than {MAX_DEPTH} levels deep",
        hint="split the task into several phrases or conjuncts",
        file=file,
        line=line,
        col=col,
    )
    if _tree_depth(tree) > MAX_DEPTH:
        raise InvalidInputError(too_deep)
    transformer = _ToAst(pos, file)
    try:
        formula = transformer.transform(tree)
    except (RecursionError, VisitError):
        raise InvalidInputError(too_deep) from None
    if transformer.problems:
        raise InvalidInputError(transformer.problems)
    if not isinstance(formula, Formula):  # pragma: no cover - the grammar always yields one
        raise InvalidInputError(error("L003", "cannot parse LTL formula", file=file))
    return formula
