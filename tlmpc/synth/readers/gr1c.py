"""gr1c's ``.spc`` format, read as gr1c reads it.

Sections ``ENV:``/``SYS:`` (variables: Boolean, or integers ``[0,n]``), ``ENVINIT ENVTRANS
ENVGOAL SYSINIT SYSTRANS SYSGOAL``, each ended by ``;``; an omitted section is empty (``True``,
``[]True``, ``[]<>True``).  Transition rules are ``[] f & [] g ...`` with primes for the next
step; goals ``[]<> f & []<> g``.  As in gr1c's grammar, ``&`` directly followed (on the same
line) by ``[]`` or ``[]<>`` starts the next conjunct, ``&`` and ``|`` have the same precedence
and group to the left, ``->`` binds weaker and ``<->`` weakest, and ``!`` applies to the operand
right after it.  Each conjunct is one part of the game (for unrealizability cores).

Initial conditions follow gr1c's ``-n`` option: ``forall_env_exists_sys`` (gr1c's default
``ALL_ENV_EXIST_SYS_INIT``: ENVINIT only over environment variables, SYSINIT only over system
ones), ``all_init`` (``ALL_INIT``) or ``one_side`` (``ONE_SIDE_INIT``: at most one of ENVINIT
and SYSINIT, both is refused, Q016).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from tlmpc.synth.readers.source import Source
from tlmpc.synth.spec import (
    Atom,
    Binary,
    Compare,
    Const,
    Expr,
    GameSpec,
    InitMode,
    Nary,
    Not,
    Owner,
    Part,
    PartKind,
    Variable,
    support,
)

_SECTIONS = {
    "ENV:": ("env", "vars"),
    "SYS:": ("sys", "vars"),
    "ENVINIT:": ("env", "init"),
    "ENVTRANS:": ("env", "safety"),
    "ENVGOAL:": ("env", "liveness"),
    "SYSINIT:": ("sys", "init"),
    "SYSTRANS:": ("sys", "safety"),
    "SYSGOAL:": ("sys", "liveness"),
}

_TOKEN = re.compile(
    r"""
    (?P<space>[ \t\r]+)
  | (?P<newline>\n)
  | (?P<comment>\#[^\n]*)
  | (?P<section>(?:ENVINIT|ENVTRANS|ENVGOAL|SYSINIT|SYSTRANS|SYSGOAL|ENV|SYS):)
  | (?P<and_live>&[ \t]*\[\]<>)
  | (?P<and_safe>&[ \t]*\[\])
  | (?P<live>\[\]<>)
  | (?P<safe>\[\])
  | (?P<eventually><>)
  | (?P<op><->|->|<=|>=|!=|[()&|!=';,<>\[\]])
  | (?P<ident>[A-Za-z_][A-Za-z0-9_.]*)
  | (?P<number>[0-9]+(?:\.[0-9]+)?)
    """,
    re.VERBOSE,
)


@dataclass(frozen=True)
class Token:
    """One lexeme: kind, text and offsets."""

    kind: str
    text: str
    start: int
    end: int


def tokenize(source: Source) -> list[Token]:
    """gr1c's lexer: section keywords only at the start of a line, comments to the end of
    line, ``&`` followed on the same line by ``[]``/``[]<>`` as one token."""
    text = source.text
    tokens: list[Token] = []
    offset = 0
    line_start = True
    while offset < len(text):
        match = _TOKEN.match(text, offset)
        if match is None:
            raise source.fail(
                "Q010",
                f"unexpected character {text[offset]!r}",
                offset,
                "gr1c specifications use identifiers, numbers, ! & | -> <-> = != < <= > >= "
                "( ) [] []<> ' ; and # comments",
            )
        kind = match.lastgroup or ""
        if kind == "newline":
            line_start = True
        elif kind == "section" and not line_start:
            raise source.fail(
                "Q010",
                f"the section keyword {match.group()!r} must begin a line",
                offset,
                "gr1c recognises ENV:, SYS:, ENVINIT:, ... only at the start of a line",
            )
        elif kind not in ("space", "comment"):
            line_start = False
            tokens.append(Token(kind, match.group(), offset, match.end()))
        offset = match.end()
    tokens.append(Token("eof", "", len(text), len(text)))
    return tokens


class _Parser:
    def __init__(self, source: Source, init_mode: InitMode) -> None:
        self.source = source
        self.tokens = tokenize(source)
        self.pos = 0
        self.init_mode = init_mode
        self.variables: dict[str, Variable] = {}
        self.parts: list[Part] = []
        #: where each player's initial condition starts (ONE_SIDE_INIT takes only one)
        self.init_starts: dict[Owner, int] = {}

    # --- token helpers --------------------------------------------------------------------

    @property
    def token(self) -> Token:
        return self.tokens[self.pos]

    def advance(self) -> Token:
        token = self.tokens[self.pos]
        self.pos += 1
        return token

    def expect(self, text: str, hint: str) -> Token:
        if self.token.text != text or self.token.kind not in ("op",):
            raise self.source.fail(
                "Q011",
                f"expected {text!r}, found {self._shown(self.token)}",
                self.token.start,
                hint,
            )
        return self.advance()

    @staticmethod
    def _shown(token: Token) -> str:
        return "the end of the file" if token.kind == "eof" else repr(token.text)

    # --- sections --------------------------------------------------------------------------

    def parse(self) -> GameSpec:
        while self.token.kind != "eof":
            token = self.advance()
            if token.kind != "section":
                raise self.source.fail(
                    "Q011",
                    f"expected a section (ENV:, SYS:, ENVINIT:, ...), found {self._shown(token)}",
                    token.start,
                    "every part of a gr1c specification is in a section that ends with ';'",
                )
            owner, what = _SECTIONS[token.text]
            if what == "vars":
                self.declarations(owner)  # type: ignore[arg-type]
            else:
                self.section(token, owner, what)  # type: ignore[arg-type]
        if not self.variables:
            raise self.source.fail(
                "Q012",
                "no variables are declared",
                0,
                "declare at least one variable in ENV: or SYS: (gr1c requires one)",
            )
        if self.init_mode == "one_side" and "env" in self.init_starts and "sys" in self.init_starts:
            raise self.source.fail(
                "Q016",
                "SYSINIT beside ENVINIT: gr1c's ONE_SIDE_INIT takes at most one of them",
                self.init_starts["sys"],
                "keep ENVINIT (every state it allows may be the first) or SYSINIT (the system "
                "picks a first state it allows), or read with --all-init (every state both "
                "allow may be the first)",
            )
        return GameSpec(
            variables=tuple(self.variables.values()),
            parts=tuple(self.parts),
            init_mode=self.init_mode,
            source_format="gr1c",
            file=self.source.file,
        )

    def declarations(self, owner: Owner) -> None:
        while not (self.token.kind == "op" and self.token.text == ";"):
            token = self.advance()
            if token.kind != "ident" or token.text in ("True", "False"):
                raise self.source.fail(
                    "Q011",
                    f"expected a variable name, found {self._shown(token)}",
                    token.start,
                    "declare variables as `ENV: a b [0,5] c;` (names, each optionally with a "
                    "range [0,n]), ended by ';'",
                )
            if token.text in self.variables:
                raise self.source.fail(
                    "Q013",
                    f"variable {token.text!r} is declared twice",
                    token.start,
                    "each variable is declared once, in ENV: or SYS:",
                )
            low = high = None
            if self.token.text == "[":
                self.advance()
                low_token = self.advance()
                self.expect(",", "a range is written [0,n]")
                high_token = self.advance()
                self.expect("]", "a range is written [0,n]")
                if low_token.kind != "number" or high_token.kind != "number":
                    raise self.source.fail(
                        "Q011", "a range's bounds must be numbers", low_token.start, "write [0,n]"
                    )
                if low_token.text != "0" and int(float(low_token.text)) != 0:
                    raise self.source.fail(
                        "Q014",
                        f"the range of {token.text!r} does not start at 0",
                        low_token.start,
                        "gr1c supports integer domains [0,n] only; shift the variable",
                    )
                low, high = 0, int(high_token.text) if high_token.text.isdigit() else -1
                if high < 0:
                    raise self.source.fail(
                        "Q014",
                        f"the upper bound of {token.text!r} is not a whole number",
                        high_token.start,
                        "write [0,n] with n a non-negative integer",
                    )
            self.variables[token.text] = Variable(token.text, owner, low, high)
        self.advance()

    def section(self, keyword: Token, owner: Owner, kind: PartKind) -> None:
        if self.token.text == ";" and self.token.kind == "op":
            self.advance()
            return
        if kind == "init":
            start = self.token.start
            formula = self.formula(allow_prime=False)
            self.add_part(owner, kind, formula, start)
        else:
            lead, lead_and = ("safe", "and_safe") if kind == "safety" else ("live", "and_live")
            first = True
            while True:
                token = self.advance()
                expected = lead if first else lead_and
                if token.kind != expected:
                    if token.kind == "eventually" or (first and token.kind == "safe"):
                        raise self.source.fail(
                            "Q015",
                            f"{keyword.text[:-1]} expects []<> goals, found {token.text!r}",
                            token.start,
                            "tlmpc synth reads gr1c's GR(1) games: write each goal as []<> f "
                            "(a one-time <> f is a reachability goal of gr1c's `rg` tool)",
                        )
                    shape = "[] f & [] g" if kind == "safety" else "[]<> f & []<> g"
                    raise self.source.fail(
                        "Q011",
                        f"expected {'[]' if kind == 'safety' else '[]<>'} to start a conjunct of "
                        f"{keyword.text[:-1]}, found {self._shown(token)}",
                        token.start,
                        f"write {keyword.text} {shape}; with '& []' on one line",
                    )
                first = False
                start = self.token.start
                formula = self.formula(allow_prime=kind == "safety")
                self.add_part(owner, kind, formula, start)
                if self.token.kind != lead_and:
                    break
        if not (self.token.kind == "op" and self.token.text == ";"):
            raise self.source.fail(
                "Q011",
                f"expected ';' to end {keyword.text[:-1]}, found {self._shown(self.token)}",
                self.token.start,
                "end each section with ';'; '& []' must be on one line to continue a rule",
            )
        self.advance()

    def add_part(self, owner: Owner, kind: PartKind, formula: Expr, start: int) -> None:
        end = self.tokens[self.pos - 1].end
        if kind == "init":
            self.init_starts.setdefault(owner, start)
        used = support(formula)
        for name, primed in sorted(used):
            variable = self.variables[name]
            wrong_init = (
                kind == "init"
                and self.init_mode == "forall_env_exists_sys"
                and variable.owner != owner
            )
            if wrong_init:
                raise self.source.fail(
                    "Q016",
                    f"{owner.upper()}INIT mentions the {variable.owner} variable {name!r}",
                    start,
                    "under gr1c's default ALL_ENV_EXIST_SYS_INIT, ENVINIT is over environment "
                    "variables and SYSINIT over system variables; move the constraint, or read "
                    "with --all-init (gr1c -n ALL_INIT)",
                )
            if kind == "safety" and owner == "env" and primed and variable.owner == "sys":
                raise self.source.fail(
                    "Q017",
                    f"ENVTRANS mentions the next value of the system variable {name!r}",
                    start,
                    "the environment moves first: its rules may read the current state and its "
                    "own next values only; move the constraint to SYSTRANS",
                )
        self.parts.append(
            Part(owner, kind, formula, self.source.location(start), self.source.excerpt(start, end))
        )

    # --- formulas --------------------------------------------------------------------------

    def formula(self, *, allow_prime: bool) -> Expr:
        return self.binary(0, allow_prime)

    _LEVELS = (("<->",), ("->",), ("&", "|"))

    def binary(self, level: int, allow_prime: bool) -> Expr:
        if level == len(self._LEVELS):
            return self.unary(allow_prime)
        left = self.binary(level + 1, allow_prime)
        while self.token.kind == "op" and self.token.text in self._LEVELS[level]:
            op = self.advance().text
            right = self.binary(level + 1, allow_prime)
            if op == "&":
                left = Nary("and", (left, right))
            elif op == "|":
                left = Nary("or", (left, right))
            else:
                left = Binary(op, left, right)  # type: ignore[arg-type]
        return left

    def unary(self, allow_prime: bool) -> Expr:
        token = self.advance()
        if token.kind == "op" and token.text == "!":
            return Not(self.unary(allow_prime))
        if token.kind == "op" and token.text == "(":
            inner = self.formula(allow_prime=allow_prime)
            self.expect(")", "close the parenthesis")
            return inner
        if token.kind == "ident" and token.text in ("True", "False"):
            return Const(token.text == "True")
        if token.kind == "ident":
            return self.variable_term(token, allow_prime)
        if token.kind in ("safe", "live", "and_safe", "and_live", "eventually"):
            raise self.source.fail(
                "Q015",
                f"temporal operator {token.text!r} inside a formula",
                token.start,
                "gr1c allows [] and []<> only at the start of each conjunct of a TRANS or GOAL "
                "section (and '& []' must stand on one line)",
            )
        raise self.source.fail(
            "Q011",
            f"expected a formula, found {self._shown(token)}",
            token.start,
            "a formula is built from variables, True, False, comparisons, ! & | -> <-> "
            "and parentheses",
        )

    def variable_term(self, token: Token, allow_prime: bool) -> Expr:
        name = token.text
        if name not in self.variables:
            raise self.source.fail(
                "Q018",
                f"undeclared variable {name!r}",
                token.start,
                "declare it in ENV: or SYS:",
            )
        variable = self.variables[name]
        primed = False
        if self.token.kind == "op" and self.token.text == "'":
            prime = self.advance()
            if not allow_prime:
                raise self.source.fail(
                    "Q019",
                    f"primed variable {name}' outside a transition rule",
                    prime.start,
                    "next values (') may appear only in ENVTRANS and SYSTRANS",
                )
            primed = True
        if self.token.kind == "op" and self.token.text in ("=", "!=", "<", "<=", ">", ">="):
            op_token = self.advance()
            number = self.advance()
            if number.kind != "number" or not number.text.isdigit():
                raise self.source.fail(
                    "Q011",
                    f"expected a whole number after {op_token.text!r}, found {self._shown(number)}",
                    number.start,
                    "gr1c compares a variable with a number: x = 3, y' != 0",
                )
            if variable.is_bool:
                raise self.source.fail(
                    "Q020",
                    f"the Boolean variable {name!r} is compared with a number",
                    token.start,
                    "give the variable a range ([0,n]) or use it as a proposition",
                )
            return Compare(name, op_token.text, int(number.text), primed)  # type: ignore[arg-type]
        if not variable.is_bool:
            raise self.source.fail(
                "Q020",
                f"the integer variable {name!r} is used as a proposition",
                token.start,
                f"compare it with a number, e.g. {name} = 0",
            )
        return Atom(name, primed)


def parse_gr1c(
    text: str, *, file: str = "<input>", init_mode: InitMode = "forall_env_exists_sys"
) -> GameSpec:
    """Read a gr1c specification."""
    return _Parser(Source(file, text), init_mode).parse()
