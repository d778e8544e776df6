"""slugs' structured format (``.structuredslugs``), read as slugs' own compiler reads it.

The sections are those of ``.slugsin``; a variable line is a Boolean ``name`` or an integer
``name: low...high`` (``0 <= low <= high``).  Each formula line is one part of the game.  As in
slugs' compiler, a line that is already a valid prefix (``.slugsin``) formula over the Boolean
variables is read as one; every other line is infix:

* precedence, lowest first, every binary operator left-associative: ``<->`` (or ``<-->``),
  ``->`` (``-->``), ``^``, ``|`` (``||``, ``\\/``), ``&`` (``&&``, ``/\\``); then the unary
  ``!`` / ``~`` and the next operator ``X`` / ``next`` / ``()``; ``TRUE``, ``FALSE``,
  brackets ``( )`` or ``[ ]``;
* ``x'`` or ``X f`` is the next value; a prime inside ``X`` and ``X`` inside ``X`` are refused;
* an atomic formula may compare sums of integer variables and numerals: ``level' = level+1``,
  ``x'+1 >= x`` with ``= != < <= > >=``.  Values are the variables' own values (the range's
  low end included) and the arithmetic is exact: slugs' compiler builds adders wide enough
  that nothing overflows.

What slugs' compiler refuses or cannot translate is refused with a located diagnostic:
temporal operators (``F G U W``, ``<>``, ``[]``), subtraction, multiplication,
``LEASTSIGNIFICANTBITOVERWRITES``, the sections of its other tools (``[OBSERVABLE_INPUT]``,
...).  The initial-state reading is slugs' (docs/synthesis.md).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Literal

from tlmpc.synth.readers.slugsin import _allowed, _formula, _Line, section_lines
from tlmpc.synth.readers.source import Source
from tlmpc.synth.spec import (
    Atom,
    Binary,
    Const,
    Expr,
    GameSpec,
    InitMode,
    Linear,
    Nary,
    Not,
    Owner,
    Part,
    PartKind,
    Variable,
)

_OTHER_TOOLS = ("[OBSERVABLE_INPUT]", "[UNOBSERVABLE_INPUT]", "[CONTROLLABLE_INPUT]")
_WORD = re.compile(r"[a-zA-Z_.'@][a-zA-Z0-9_.'@]*")
_NUMBER = re.compile(r"[0-9]+")
_KEYWORDS = frozenset(
    {"X", "F", "G", "U", "W", "FALSE", "TRUE", "next", "LEASTSIGNIFICANTBITOVERWRITES"}
)
_RANGE = re.compile(r"^\s*(-?\d+)\s*\.\.\.\s*(-?\d+)\s*$")

CompareOp = Literal["=", "!=", "<", "<=", ">", ">="]


@dataclass(frozen=True)
class _Token:
    kind: Literal["word", "keyword", "number", "char", "end"]
    text: str
    offset: int


class _Backtrack(Exception):
    """An attempt to read an arithmetic comparison failed; read a formula instead."""


def _tokens(text: str, start: int) -> list[_Token]:
    found: list[_Token] = []
    k = 0
    while k < len(text):
        ch = text[k]
        if ch.isspace():
            k += 1
            continue
        word = _WORD.match(text, k)
        if word:
            kind: Literal["word", "keyword"] = "keyword" if word.group(0) in _KEYWORDS else "word"
            found.append(_Token(kind, word.group(0), start + k))
            k = word.end()
            continue
        number = _NUMBER.match(text, k)
        if number:
            found.append(_Token("number", number.group(0), start + k))
            k = number.end()
            continue
        found.append(_Token("char", ch, start + k))
        k += 1
    found.append(_Token("end", "", start + len(text)))
    return found


class _Infix:
    """A recursive-descent reader of one infix line (slugs' grammar)."""

    def __init__(
        self,
        source: Source,
        tokens: list[_Token],
        variables: dict[str, Variable],
        owner: Owner,
        kind: PartKind,
    ) -> None:
        self.source = source
        self.tokens = tokens
        self.pos = 0
        self.variables = variables
        self.owner = owner
        self.kind = kind
        self.attempting = 0  # > 0 while reading a comparison that may be backtracked

    # --- tokens -------------------------------------------------------------------------

    def peek(self, ahead: int = 0) -> _Token:
        return self.tokens[min(self.pos + ahead, len(self.tokens) - 1)]

    def chars(self, *sequence: str) -> bool:
        """Whether the next tokens are exactly these single characters (then consume them)."""
        for k, ch in enumerate(sequence):
            token = self.peek(k)
            if token.kind != "char" or token.text != ch:
                return False
        self.pos += len(sequence)
        return True

    def fail(self, code: str, message: str, token: _Token, hint: str) -> Exception:
        if self.attempting:
            return _Backtrack()
        return self.source.fail(code, message, token.offset, hint)

    def expected(self, what: str) -> Exception:
        token = self.peek()
        found = "the end of the line" if token.kind == "end" else repr(token.text)
        return self.fail(
            "Q130",
            f"expected {what}, found {found}",
            token,
            "infix formulas: ! & | ^ -> <->, X or ' for next, TRUE/FALSE, brackets, and "
            "comparisons of sums of integer variables and numbers (x' = x + 1)",
        )

    # --- formulas -----------------------------------------------------------------------

    def line(self) -> Expr:
        formula = self.biimplication(False)
        if self.peek().kind != "end":
            raise self.expected("an operator or the end of the line")
        return formula

    def biimplication(self, primed: bool) -> Expr:
        left = self.implication(primed)
        while self.chars("<", "-", "-", ">") or self.chars("<", "-", ">"):
            left = Binary("<->", left, self.implication(primed))
        return left

    def implication(self, primed: bool) -> Expr:
        left = self.xor(primed)
        while self.chars("-", "-", ">") or self.chars("-", ">"):
            left = Binary("->", left, self.xor(primed))
        return left

    def xor(self, primed: bool) -> Expr:
        left = self.disjunction(primed)
        while self.chars("^"):
            left = Nary("xor", (left, self.disjunction(primed)))
        return left

    def disjunction(self, primed: bool) -> Expr:
        left = self.conjunction(primed)
        while self.chars("\\", "/") or self.chars("|", "|") or self.chars("|"):
            left = Nary("or", (left, self.conjunction(primed)))
        return left

    def conjunction(self, primed: bool) -> Expr:
        left = self.temporal(primed)
        while self.chars("/", "\\") or self.chars("&", "&") or self.chars("&"):
            left = Nary("and", (left, self.temporal(primed)))
        return left

    def temporal(self, primed: bool) -> Expr:
        left = self.unary(primed)
        token = self.peek()
        if token.kind == "keyword" and token.text in ("U", "W"):
            raise self._temporal(token)
        return left

    def _temporal(self, token: _Token) -> Exception:
        return self.fail(
            "Q134",
            f"the temporal operator {token.text!r} has no place in a GR(1) part",
            token,
            "each line is one initial condition, safety constraint (with ' or X for the next "
            "step) or liveness goal of its section; write F/G/U/W away (slugs refuses them)",
        )

    def unary(self, primed: bool) -> Expr:
        token = self.peek()
        if self.chars("!") or self.chars("~"):
            return Not(self.unary(primed))
        next_word = token.kind == "keyword" and token.text in ("X", "next")
        if next_word or self.chars("(", ")"):
            if next_word:
                self.pos += 1
            if primed:
                raise self.fail(
                    "Q134",
                    "a next operator inside another one",
                    token,
                    "slugs reads one step ahead at most: X (X a) has no meaning here",
                )
            return self.unary(True)
        if token.kind == "keyword" and token.text in ("F", "G"):
            raise self._temporal(token)
        if self.peek().text == "<" and self.peek(1).text == ">":
            raise self._temporal(_Token("char", "<>", token.offset))
        if self.peek().text == "[" and self.peek(1).text == "]":
            raise self._temporal(_Token("char", "[]", token.offset))
        return self.atomic(primed)

    def atomic(self, primed: bool) -> Expr:
        token = self.peek()
        if token.kind == "keyword" and token.text in ("TRUE", "FALSE"):
            self.pos += 1
            return Const(token.text == "TRUE")
        if token.kind == "word" and self._boolean(token.text):
            self.pos += 1
            return self.atom(token, primed)
        if token.kind == "char" and token.text in ("(", "["):
            if token.text == "(":
                saved = self.pos
                self.attempting += 1
                try:
                    return self.comparison(primed)
                except _Backtrack:
                    self.pos = saved
                finally:
                    self.attempting -= 1
            self.pos += 1
            inner = self.biimplication(primed)
            if not self.chars(")" if token.text == "(" else "]"):
                raise self.expected(f"a closing {')' if token.text == '(' else ']'}")
            return inner
        if token.kind in ("word", "number"):
            return self.comparison(primed)
        raise self.expected("a formula")

    def _boolean(self, word: str) -> bool:
        name = word[:-1] if word.endswith("'") else word
        variable = self.variables.get(name)
        return variable is not None and variable.is_bool

    def atom(self, token: _Token, primed: bool) -> Expr:
        word = token.text
        name = word[:-1] if word.endswith("'") else word
        variable = self.variables[name]
        local = word.endswith("'")
        if local and primed:
            raise self.fail(
                "Q134",
                f"{word!r} is primed inside a next operator",
                token,
                "write either x' or X x, not both",
            )
        self.check(variable, local or primed, token)
        return Atom(name, local or primed)

    def check(self, variable: Variable, primed: bool, token: _Token) -> None:
        reason = _allowed(variable, primed, self.owner, self.kind)
        if reason is not None:
            raise self.fail(
                "Q136",
                f"{token.text!r} is not allowed here: {reason}",
                token,
                "move the constraint to the section that may mention it (see docs/synthesis.md)",
            )

    # --- arithmetic ---------------------------------------------------------------------

    def comparison(self, primed: bool) -> Expr:
        left_terms, left_value = self.sum(primed)
        token = self.peek()
        op: CompareOp
        if self.chars("<", "="):
            op = "<="
        elif self.chars(">", "="):
            op = ">="
        elif self.chars("!", "="):
            op = "!="
        elif self.chars("="):
            op = "="
        elif token.text == "<" and self.peek(1).text != "-" and self.chars("<"):
            op = "<"
        elif self.chars(">"):
            op = ">"
        else:
            raise self.expected("a comparison (= != < <= > >=)")
        right_terms, right_value = self.sum(primed)
        coefs: dict[tuple[str, bool], int] = dict(left_terms)
        for key, coef in right_terms.items():
            coefs[key] = coefs.get(key, 0) - coef
        terms = tuple((c, name, p) for (name, p), c in sorted(coefs.items()) if c != 0)
        return Linear(terms, op, right_value - left_value)

    def sum(self, primed: bool) -> tuple[dict[tuple[str, bool], int], int]:
        terms, value = self.number(primed)
        while True:
            token = self.peek()
            if self.chars("+"):
                more, extra = self.number(primed)
                for key, coef in more.items():
                    terms[key] = terms.get(key, 0) + coef
                value += extra
            elif token.text == "-" and self.peek(1).text not in ("-", ">"):
                raise self._unsupported(token, "subtraction")
            elif token.text == "*":
                raise self._unsupported(token, "multiplication")
            elif token.text == "LEASTSIGNIFICANTBITOVERWRITES":
                raise self._unsupported(token, "LEASTSIGNIFICANTBITOVERWRITES")
            else:
                return terms, value

    def _unsupported(self, token: _Token, what: str) -> Exception:
        return self.fail(
            "Q135",
            f"{what} is not supported in comparisons",
            token,
            "slugs' compiler translates sums of variables and numbers only: move the term to "
            "the other side (x' + 1 = x instead of x' = x - 1)",
        )

    def number(self, primed: bool) -> tuple[dict[tuple[str, bool], int], int]:
        token = self.peek()
        if token.kind == "number":
            self.pos += 1
            return {}, int(token.text)
        if token.kind == "char" and token.text == "(":
            self.pos += 1
            terms, value = self.sum(primed)
            if not self.chars(")"):
                raise self.expected("a closing )")
            return terms, value
        if token.kind == "word":
            word = token.text
            name = word[:-1] if word.endswith("'") else word
            variable = self.variables.get(name)
            if variable is None:
                raise self.fail(
                    "Q133",
                    f"the variable {name!r} is not declared",
                    token,
                    "declare it under [INPUT] or [OUTPUT] (name, or name: low...high)",
                )
            if variable.is_bool:
                raise self.fail(
                    "Q133",
                    f"{name!r} is Boolean, not a number",
                    token,
                    "compare integer variables (declared name: low...high) and numbers",
                )
            local = word.endswith("'")
            if local and primed:
                raise self.fail(
                    "Q134",
                    f"{word!r} is primed inside a next operator",
                    token,
                    "write either x' or X x, not both",
                )
            self.check(variable, local or primed, token)
            self.pos += 1
            return {(name, local or primed): 1}, 0
        raise self.expected("an integer variable or a number")


def _prefix_line(tokens: list[str], booleans: set[str]) -> bool:
    """slugs' own test: a line is already prefix when reading it right to left leaves one
    formula on the stack (or it uses a memory buffer ``$``)."""
    if "$" in tokens:
        return True
    depth = 0
    for token in reversed(tokens):
        if token in ("|", "&", "^"):
            if depth < 2:
                return False
            depth -= 1
        elif token == "!":
            continue
        elif token in ("0", "1") or token.removesuffix("'") in booleans:
            depth += 1
        else:
            return False
    return depth == 1


def parse_structuredslugs(
    text: str, *, file: str = "<input>", init_mode: InitMode = "forall_env_exists_sys"
) -> GameSpec:
    """Read a slugs structured specification."""
    source = Source(file, text)
    variables: dict[str, Variable] = {}
    parts: list[Part] = []
    for owner, what, stripped, start in section_lines(
        source,
        text,
        code="Q131",
        unknown_hint="structuredslugs sections are [INPUT] [OUTPUT] [ENV_INIT] [SYS_INIT] "
        "[ENV_TRANS] [SYS_TRANS] [ENV_LIVENESS] [SYS_LIVENESS]",
        first_hint="start the file with [INPUT]",
        other_tools=_OTHER_TOOLS,
    ):
        if what == "vars":
            variable = _declaration(source, stripped, start, owner, variables)
            variables[variable.name] = variable
            continue
        kind: PartKind = what  # type: ignore[assignment]
        booleans = {name for name, v in variables.items() if v.is_bool}
        formula: Expr
        if _prefix_line([t for t in stripped.split(" ") if t], booleans):
            line = _Line(source, start, stripped)
            only_booleans = {n: v for n, v in variables.items() if v.is_bool}
            formula = _formula(line, [], only_booleans, owner, kind)
            if line.pos != len(line.tokens):
                word, where = line.tokens[line.pos]
                raise source.fail(
                    "Q130",
                    f"stray text after the prefix formula: {word!r}",
                    where,
                    "a line read as prefix (slugsin) holds exactly one formula",
                )
        else:
            for token in _tokens(stripped, start):
                if "@" in token.text:
                    raise source.fail(
                        "Q135",
                        f"{token.text!r} names a bit of an integer variable",
                        token.offset,
                        "compare the integer variable itself (x = 3, x' >= x + 1)",
                    )
            formula = _Infix(source, _tokens(stripped, start), variables, owner, kind).line()
        parts.append(Part(owner, kind, formula, source.location(start), stripped))
    return GameSpec(
        variables=tuple(variables.values()),
        parts=tuple(parts),
        init_mode=init_mode,
        source_format="structuredslugs",
        file=file,
    )


def _declaration(
    source: Source, text: str, start: int, owner: Owner, known: dict[str, Variable]
) -> Variable:
    name, colon, bounds = text.partition(":")
    name = name.strip()
    if not _WORD.fullmatch(name) or "'" in name or "@" in name or name in _KEYWORDS:
        raise source.fail(
            "Q132",
            f"{name!r} is not a variable name",
            start,
            "a name is letters, digits, '_' and '.', not starting with a digit, without ' or @, "
            "and not one of X F G U W TRUE FALSE next",
        )
    if name in known:
        raise source.fail(
            "Q132", f"{name!r} is declared twice", start, "declare each variable once"
        )
    if not colon:
        return Variable(name, owner)
    found = _RANGE.match(bounds)
    where = start + len(text) - len(bounds.lstrip())
    if found is None:
        raise source.fail(
            "Q132",
            f"cannot read the range {bounds.strip()!r} of {name!r}",
            where,
            "write an integer variable as name: low...high (for example level: 3...107)",
        )
    low, high = int(found.group(1)), int(found.group(2))
    if low < 0 or low > high:
        raise source.fail(
            "Q132",
            f"the range {low}...{high} of {name!r} is " + ("negative" if low < 0 else "empty"),
            where,
            "slugs' integers range over 0 <= low <= high",
        )
    return Variable(name, owner, low, high)
