"""GR(1)-shaped TLSF (SYNTCOMP's format, basic fragment), read as syfco hands it to GR(1) tools.

A basic TLSF file has ``INFO`` (``SEMANTICS: Mealy`` or ``Mealy,Strict``) and ``MAIN`` with
``INPUTS``/``OUTPUTS`` and formula sections, each formula ended by ``;`` (sections may repeat).
Its meaning (TLSF 1.1) is ``INITIALLY -> (PRESET /\\ (ASSERT W ~REQUIRE) /\\ ((G REQUIRE /\\
ASSUME) -> GUARANTEE))`` under strict semantics.  The GR(1) game reads it as syfco's
GR(1) translation does (the one SYNTCOMP feeds GR(1) tools with):

* ``INITIALLY``: the environment's initial condition (inputs only);
* ``PRESET``: the system's initial condition;
* ``REQUIRE``: environment safety (implicitly under ``G``; ``X`` only over inputs);
* ``ASSERT``: system safety (implicitly under ``G``; ``X`` over anything);
* ``ASSUME`` / ``GUARANTEE``: conjunctions of ``G F b`` (liveness) and ``G s`` (safety).

Anything else is outside GR(1) and refused with a diagnostic saying why and how to rewrite it.
So is a file whose meaning the game would not decide exactly (Q047, :func:`_undecided`: e.g.
non-strict system safety beside assumptions, or a ``G s`` in GUARANTEE under ASSUME).
Parametric TLSF (a non-empty ``GLOBAL``) and Moore semantics are refused as well.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

from tlmpc.base.errors import UsageError
from tlmpc.synth.readers.source import Source
from tlmpc.synth.spec import (
    Atom,
    Binary,
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
)

_TOKEN = re.compile(
    r"""
    (?P<space>\s+)
  | (?P<comment>//[^\n]*|/\*.*?\*/)
  | (?P<string>"[^"]*")
  | (?P<op>&&|\|\||<->|->|[!{}();:,])
  | (?P<ident>[A-Za-z_][A-Za-z0-9_@']*)
  | (?P<number>[0-9]+)
    """,
    re.VERBOSE | re.DOTALL,
)
_WORD_OPS = {"NOT": "!", "AND": "&&", "OR": "||", "IMPLIES": "->", "EQUIV": "<->"}
_UNARY = {"!", "X", "G", "F"}
_BINARY_TEMPORAL = {"U", "W", "R"}
_RESERVED = _UNARY.union(_BINARY_TEMPORAL, {"true", "false"}) - {"!"}


@dataclass(frozen=True)
class Token:
    """One lexeme."""

    kind: str
    text: str
    start: int
    end: int


@dataclass(frozen=True, eq=False)
class Node:
    """A TLSF formula node: ``op`` is ``ap``, ``const``, ``!``, ``&&``, ``||``, ``->``,
    ``<->``, ``X``, ``G``, ``F``, ``U``, ``W`` or ``R``.

    ``start`` is where the node's operator (or atom) is written, the place of a diagnostic
    about it; ``span`` the offsets of the whole formula as written, from its first to the end
    of its last token, parentheses around it included (a part's location and text)."""

    op: str
    args: tuple[Node, ...]
    start: int
    span: tuple[int, int]
    name: str = ""
    value: bool = False


def tokenize(source: Source) -> list[Token]:
    """TLSF's lexemes (comments and whitespace dropped)."""
    text = source.text
    tokens: list[Token] = []
    offset = 0
    while offset < len(text):
        match = _TOKEN.match(text, offset)
        if match is None:
            # kept as a token: the parser says where it stops making sense (a parametric
            # GLOBAL section is refused as such before its '=' is reached)
            tokens.append(Token("other", text[offset], offset, offset + 1))
            offset += 1
            continue
        kind = match.lastgroup or ""
        if kind not in ("space", "comment"):
            word = match.group()
            if kind == "ident" and word in _WORD_OPS:
                kind, word = "op", _WORD_OPS[word]
            tokens.append(Token(kind, word, offset, match.end()))
        offset = match.end()
    tokens.append(Token("eof", "", len(text), len(text)))
    return tokens


class _Parser:
    def __init__(self, source: Source) -> None:
        self.source = source
        self.tokens = tokenize(source)
        self.pos = 0

    @property
    def token(self) -> Token:
        return self.tokens[self.pos]

    def advance(self) -> Token:
        token = self.tokens[self.pos]
        self.pos += 1
        return token

    def shown(self, token: Token) -> str:
        return "the end of the file" if token.kind == "eof" else repr(token.text)

    def expect(self, text: str, hint: str) -> Token:
        if self.token.text != text or self.token.kind not in ("op", "ident"):
            raise self.source.fail(
                "Q041", f"expected {text!r}, found {self.shown(self.token)}", self.token.start, hint
            )
        return self.advance()

    # formulas: unary > && > || > (-> <->, right) > W > U > R
    _LEVELS: tuple[tuple[str, ...], ...] = (("R",), ("U",), ("W",), ("->", "<->"), ("||",), ("&&",))

    def formula(self, level: int = 0) -> Node:
        if level == len(self._LEVELS):
            return self.unary()
        ops = self._LEVELS[level]
        left = self.formula(level + 1)
        if self.token.text in ops and self.token.kind in ("op", "ident"):
            op = self.advance()
            right_assoc = op.text != "R" and op.text not in ("&&", "||")
            if right_assoc:
                right = self.formula(level)
                return Node(op.text, (left, right), op.start, (left.span[0], right.span[1]))
            right = self.formula(level + 1)
            left = Node(op.text, (left, right), op.start, (left.span[0], right.span[1]))
            while self.token.text in ops and self.token.kind in ("op", "ident"):
                op = self.advance()
                right = self.formula(level + 1)
                left = Node(op.text, (left, right), op.start, (left.span[0], right.span[1]))
        return left

    def unary(self) -> Node:
        token = self.advance()
        if token.text in _UNARY and token.kind in ("op", "ident"):
            operand = self.unary()
            return Node(token.text, (operand,), token.start, (token.start, operand.span[1]))
        if token.text == "(" and token.kind == "op":
            inner = self.formula()
            close = self.expect(")", "close the parenthesis")
            return replace(inner, span=(token.start, close.end))
        if token.kind == "ident" and token.text in ("true", "false"):
            return Node(
                "const", (), token.start, (token.start, token.end), value=token.text == "true"
            )
        if token.kind == "ident" and token.text not in _BINARY_TEMPORAL:
            if self.token.text == "[" or self.token.text == "(":
                raise self.source.fail(
                    "Q042",
                    f"{token.text!r} is applied like a function or a bus",
                    token.start,
                    "only basic TLSF is read: expand parametric TLSF first "
                    "(syfco -f basic spec.tlsf)",
                )
            return Node("ap", (), token.start, (token.start, token.end), name=token.text)
        if token.kind == "other":
            raise self.source.fail(
                "Q040",
                f"unexpected character {token.text!r}",
                token.start,
                "basic TLSF uses identifiers, ! && || -> <-> X G F U W R, parentheses, "
                "braces, ';' and // or /* */ comments",
            )
        raise self.source.fail(
            "Q041",
            f"expected a formula, found {self.shown(token)}",
            token.start,
            "a formula is built from signals, true, false, ! && || -> <-> X G F U W R "
            "and parentheses",
        )

    # --- the file ------------------------------------------------------------------------

    def parse(self) -> tuple[str, list[tuple[str, Token]], list[tuple[str, Node]]]:
        semantics: str | None = None
        info: Token | None = None
        main: Token | None = None
        signals: list[tuple[str, Token]] = []
        formulas: list[tuple[str, Node]] = []
        while self.token.kind != "eof":
            head = self.advance()
            if head.text == "INFO":
                info = head
                semantics = self.info()
            elif head.text == "GLOBAL":
                self.expect("{", "GLOBAL { ... }")
                if self.token.text != "}":
                    raise self.source.fail(
                        "Q042",
                        "parametric TLSF (GLOBAL with parameters or definitions)",
                        head.start,
                        "only basic TLSF is read: expand it first (syfco -f basic spec.tlsf)",
                    )
                self.advance()
            elif head.text == "MAIN":
                main = head
                self.main(signals, formulas)
            else:
                raise self.source.fail(
                    "Q041",
                    f"expected INFO, GLOBAL or MAIN, found {self.shown(head)}",
                    head.start,
                    "a TLSF file is INFO { ... } GLOBAL { ... } MAIN { ... }",
                )
        # the game's meaning hangs on SEMANTICS (strict or not), and an empty file would
        # otherwise read as the trivially realizable game
        if main is None:
            missing = "neither an INFO nor a MAIN section" if info is None else "no MAIN section"
            raise self.source.fail(
                "Q041",
                f"the file has {missing}",
                self.token.start,
                "a TLSF file is INFO { SEMANTICS: Mealy,Strict } MAIN { INPUTS { ... } ... }",
            )
        if semantics is None:
            where = "INFO does not declare it" if info is not None else "the file has no INFO"
            raise self.source.fail(
                "Q041",
                f"SEMANTICS is missing: {where}",
                main.start if info is None else info.start,
                "declare INFO { SEMANTICS: Mealy,Strict } before MAIN (plain Mealy is the "
                "non-strict reading)",
            )
        return semantics, signals, formulas

    def info(self) -> str | None:
        self.expect("{", "INFO { TITLE: ... SEMANTICS: ... }")
        semantics: str | None = None
        while self.token.text != "}":
            key = self.advance()
            if key.kind == "eof":
                raise self.source.fail("Q041", "INFO is not closed", key.start, "add '}'")
            if key.text == "SEMANTICS":
                self.expect(":", "SEMANTICS: Mealy")
                words = [self.advance()]
                while self.token.text == ",":
                    self.advance()
                    words.append(self.advance())
                semantics = ",".join(w.text for w in words)
                if words[0].text != "Mealy":
                    raise self.source.fail(
                        "Q043",
                        f"SEMANTICS {semantics}: only Mealy semantics is read",
                        words[0].start,
                        "the system answers the inputs of the same step (Mealy); convert a Moore "
                        "specification with syfco's -os option",
                    )
        self.advance()
        return semantics

    def main(self, signals: list[tuple[str, Token]], formulas: list[tuple[str, Node]]) -> None:
        self.expect("{", "MAIN { INPUTS { ... } ... }")
        while self.token.text != "}":
            head = self.advance()
            name = head.text
            if name in ("INPUTS", "OUTPUTS"):
                self.expect("{", f"{name} {{ a; b; }}")
                while self.token.text != "}":
                    signal = self.advance()
                    if signal.kind != "ident":
                        raise self.source.fail(
                            "Q041",
                            f"expected a signal name, found {self.shown(signal)}",
                            signal.start,
                            f"{name} {{ a; b; }} (basic TLSF has no buses or enums)",
                        )
                    if signal.text in _RESERVED:
                        # a formula would read the name as the operator or constant
                        raise self.source.fail(
                            "Q041",
                            f"the signal name {signal.text!r} is a TLSF keyword",
                            signal.start,
                            "rename the signal (true, false, X, G, F, U, W and R are reserved)",
                        )
                    self.expect(";", "end each signal with ';'")
                    signals.append((name, signal))
                self.advance()
            elif name in (
                "INITIALLY",
                "PRESET",
                "REQUIRE",
                "ASSERT",
                "INVARIANTS",
                "ASSUME",
                "ASSUMPTIONS",
                "GUARANTEE",
                "GUARANTEES",
            ):
                self.expect("{", f"{name} {{ formula; ... }}")
                while self.token.text != "}":
                    formula = self.formula()
                    self.expect(";", "end each formula with ';'")
                    formulas.append((name, formula))
                self.advance()
            else:
                raise self.source.fail(
                    "Q041",
                    f"unknown section {self.shown(head)} in MAIN",
                    head.start,
                    "MAIN holds INPUTS OUTPUTS INITIALLY PRESET REQUIRE ASSERT ASSUME GUARANTEE",
                )
        self.advance()


_SECTION_ROLE: dict[str, tuple[Owner, str]] = {
    "INITIALLY": ("env", "init"),
    "PRESET": ("sys", "init"),
    "REQUIRE": ("env", "safety"),
    "ASSERT": ("sys", "safety"),
    "INVARIANTS": ("sys", "safety"),
    "ASSUME": ("env", "temporal"),
    "ASSUMPTIONS": ("env", "temporal"),
    "GUARANTEE": ("sys", "temporal"),
    "GUARANTEES": ("sys", "temporal"),
}


class _Lowering:
    """From TLSF formulas to game parts, with GR(1)-shape diagnostics."""

    def __init__(self, source: Source, variables: dict[str, Variable]) -> None:
        self.source = source
        self.variables = variables

    def fail(self, node: Node, message: str, hint: str) -> UsageError:
        return self.source.fail("Q044", message, node.start, hint)

    def boolean(self, node: Node, owner: Owner, kind: str, primed: bool = False) -> Expr:
        """A Boolean formula, ``X`` allowed once (``kind`` safety), as an IR expression."""
        op = node.op
        if op == "const":
            return Const(node.value)
        if op == "ap":
            if node.name not in self.variables:
                raise self.source.fail(
                    "Q045",
                    f"the signal {node.name!r} is not declared",
                    node.start,
                    "declare it in INPUTS or OUTPUTS",
                )
            variable = self.variables[node.name]
            if kind == "init" and owner == "env" and variable.owner == "sys":
                raise self.fail(
                    node,
                    f"INITIALLY mentions the output {node.name!r}",
                    "INITIALLY constrains the first inputs only; put conditions on outputs in "
                    "PRESET",
                )
            if kind == "safety" and owner == "env" and primed and variable.owner == "sys":
                raise self.fail(
                    node,
                    f"REQUIRE mentions the next value of the output {node.name!r}",
                    "the environment moves first: REQUIRE may apply X to inputs only",
                )
            return Atom(node.name, primed)
        if op == "!":
            return Not(self.boolean(node.args[0], owner, kind, primed))
        if op in ("&&", "||"):
            return Nary(
                "and" if op == "&&" else "or",
                tuple(self.boolean(a, owner, kind, primed) for a in node.args),
            )
        if op in ("->", "<->"):
            left, right = (self.boolean(a, owner, kind, primed) for a in node.args)
            return Binary(op, left, right)  # type: ignore[arg-type]
        if op == "X":
            if kind != "safety":
                raise self.fail(
                    node,
                    "X in an initial condition or a goal",
                    "X belongs in REQUIRE, ASSERT or G safety formulas; an initial condition "
                    "speaks of the first step only",
                )
            if primed:
                raise self.fail(
                    node,
                    "nested X: GR(1) safety relates a step to the next one only",
                    "add an output that remembers the previous value (ASSERT { X m <-> a; }) and "
                    "use it in place of the inner X",
                )
            return self.boolean(node.args[0], owner, kind, True)
        raise self.fail(node, *self.why_not_gr1(node))

    @staticmethod
    def why_not_gr1(node: Node) -> tuple[str, str]:
        """Why a temporal shape is outside GR(1), and the rewrite to suggest."""
        op = node.op
        if op == "F" and node.args[0].op == "G":
            return (
                "F G (persistence) is outside GR(1)",
                "GR(1) goals are G F b; G F b is the nearest goal, or make the persistence an "
                "assumption-free safety (G b) if it must hold from the start",
            )
        if op == "F":
            return (
                "a one-time F is outside GR(1)",
                "write G F b if repeating is acceptable, or latch it in an output: ASSERT { X done "
                "<-> (done || X b); } GUARANTEE { G F done; }",
            )
        if op == "G" and node.args[0].op in ("->", "||"):
            return (
                "G with an eventuality inside (a response) is outside GR(1)",
                "add an output p that stays up while a request waits: ASSERT { X p <-> "
                "((p || a) && !X b); } GUARANTEE { G F !p; }",
            )
        if op in ("U", "W", "R"):
            return (
                f"the operator {op} is outside GR(1)",
                "express it with an auxiliary output that records the obligation, a safety "
                "formula on it, and a G F goal that discharges it",
            )
        return (
            f"{op} here is outside GR(1)",
            "GR(1) parts are Boolean initial conditions, G safety with one X, and G F goals",
        )

    def conjuncts(self, node: Node) -> list[Node]:
        if node.op == "&&":
            return [c for a in node.args for c in self.conjuncts(a)]
        return [node]

    @staticmethod
    def is_boolean(node: Node, allow_x: bool) -> bool:
        if node.op in ("ap", "const"):
            return True
        if node.op == "X":
            return allow_x and _Lowering.is_boolean(node.args[0], False)
        if node.op in ("!", "&&", "||", "->", "<->"):
            return all(_Lowering.is_boolean(a, allow_x) for a in node.args)
        return False

    def parts(self, section: str, node: Node) -> list[tuple[Owner, PartKind, Expr, Node]]:
        owner, role = _SECTION_ROLE[section]
        if role == "init":
            return [(owner, "init", self.boolean(node, owner, "init"), node)]
        if role == "safety":
            while node.op == "G":
                node = node.args[0]
            return [(owner, "safety", self.boolean(node, owner, "safety"), node)]
        found: list[tuple[Owner, PartKind, Expr, Node]] = []
        for part in self.conjuncts(node):
            if part.op == "G" and part.args[0].op == "F":
                goal = part.args[0].args[0]
                if not self.is_boolean(goal, allow_x=False):
                    raise self.fail(goal, *self.why_not_gr1(goal))
                found.append((owner, "liveness", self.boolean(goal, owner, "liveness"), goal))
            elif part.op == "G" and self.is_boolean(part.args[0], allow_x=True):
                inner = part.args[0]
                found.append((owner, "safety", self.boolean(inner, owner, "safety"), inner))
            elif part.op == "G":
                raise self.fail(part, *self.why_not_gr1(part))
            elif self.is_boolean(part, allow_x=False):
                where = "INITIALLY" if owner == "env" else "PRESET"
                raise self.fail(
                    part,
                    f"a formula without G in {section}",
                    f"in {section} it would hold only under the assumptions' implication; write "
                    f"an initial condition in {where}, or G b for every step",
                )
            else:
                raise self.fail(part, *self.why_not_gr1(part))
        return found


def parse_tlsf(
    text: str, *, file: str = "<input>", init_mode: InitMode = "forall_env_exists_sys"
) -> GameSpec:
    """Read a basic, GR(1)-shaped TLSF specification."""
    source = Source(file, text)
    parser = _Parser(source)
    semantics, signals, formulas = parser.parse()
    variables: dict[str, Variable] = {}
    for section, token in signals:
        if token.text in variables:
            raise source.fail(
                "Q046",
                f"the signal {token.text!r} is declared twice",
                token.start,
                "declare each signal once, as an input or an output",
            )
        variables[token.text] = Variable(token.text, "env" if section == "INPUTS" else "sys")
    lowering = _Lowering(source, variables)
    parts: list[Part] = []
    roles: dict[str, list[tuple[Node, Node]]] = {}
    for section, node in formulas:
        for owner, kind, expr, origin in lowering.parts(section, node):
            start, end = origin.span
            parts.append(
                Part(owner, kind, expr, source.location(start), source.excerpt(start, end))
            )
            roles.setdefault(_role(section, kind), []).append((node, origin))
    undecided = _undecided("Strict" in semantics.split(","), roles)
    if undecided is not None:
        where, message, hint = undecided
        raise source.fail("Q047", message, where.span[0], hint)
    return GameSpec(
        variables=tuple(variables.values()),
        parts=tuple(parts),
        init_mode=init_mode,
        source_format="tlsf",
        file=file,
    )


def _role(section: str, kind: PartKind) -> str:
    """A part's place in TLSF's meaning: its section, and for ASSUME and GUARANTEE whether it
    is a ``G`` (safety) or a ``G F`` (goal) conjunct."""
    section = {"INVARIANTS": "ASSERT", "ASSUMPTIONS": "ASSUME", "GUARANTEES": "GUARANTEE"}.get(
        section, section
    )
    if section in ("ASSUME", "GUARANTEE"):
        return f"{section} {'G F' if kind == 'liveness' else 'G'}"
    return section


def _undecided(
    strict: bool, roles: dict[str, list[tuple[Node, Node]]]
) -> tuple[Node, str, str] | None:
    """Where the GR(1) game would decide something else than the TLSF file means: the part to
    blame, why, and the rewrite; None when the game decides exactly the file's meaning.

    TLSF means (syfco's ``merge``, the formulas as written, empty conjunctions true)
    ``INITIALLY -> (PRESET && ((G REQUIRE && ASSUME) -> (G ASSERT && GUARANTEE)))``, and under
    strict semantics ``INITIALLY -> (PRESET && (ASSERT W !REQUIRE) && ((G REQUIRE && ASSUME)
    -> GUARANTEE))``.  The game decides ``INITIALLY -> (PRESET && (S W !E) && ((G E && G F
    a...) -> G F g...))`` with E = REQUIRE and ASSUME's ``G`` parts, S = ASSERT and
    GUARANTEE's ``G`` parts.  Term by term the two agree exactly when

    * non-strict: S is empty, or nothing conditions it (no REQUIRE, no ASSUME);
    * strict: GUARANTEE's ``G`` parts are conditioned by nothing (no REQUIRE, no ASSUME),
      ASSUME's ``G`` parts release no ASSERT (there is none), and ``ASSERT W !REQUIRE`` is
      ``a W !r`` of the steps' formulas (no ``G`` on top of either side when both are there).

    Otherwise the file's meaning is an implication between safety and the other side's
    assumptions, which a GR(1) game does not decide in general, and the file is refused.
    """

    def first(*names: str) -> Node | None:
        found = [origin for name in names for _, origin in roles.get(name, ())]
        return min(found, key=lambda n: n.span[0]) if found else None

    conditions = first("REQUIRE", "ASSUME G", "ASSUME G F")
    if not strict:
        safety = first("ASSERT", "GUARANTEE G")
        if safety is not None and conditions is not None:
            return (
                safety,
                "non-strict semantics: the system's safety must hold only while the "
                "environment keeps REQUIRE and ASSUME (G REQUIRE && ASSUME -> G ASSERT && "
                "GUARANTEE), an implication the GR(1) game does not decide",
                "declare SEMANTICS: Mealy,Strict and write the system's safety in ASSERT: it "
                "then holds until the environment breaks REQUIRE, the reading GR(1) tools use",
            )
        return None
    guarantee_safety = first("GUARANTEE G")
    if guarantee_safety is not None and conditions is not None:
        return (
            guarantee_safety,
            "G in GUARANTEE must hold only while the environment keeps REQUIRE and ASSUME "
            "(G REQUIRE && ASSUME -> GUARANTEE), an implication the GR(1) game does not decide",
            "write it in ASSERT: it then holds until the environment breaks REQUIRE, the "
            "reading GR(1) tools use",
        )
    assume_safety = first("ASSUME G")
    if assume_safety is not None and "ASSERT" in roles:
        return (
            assume_safety,
            "G in ASSUME beside ASSERT: ASSERT must hold until REQUIRE is broken, whatever "
            "ASSUME's safety does, and the GR(1) game would release it when ASSUME's safety "
            "is broken",
            "write the environment's safety in REQUIRE: ASSERT then holds until it is broken",
        )
    if "ASSERT" in roles and "REQUIRE" in roles:
        for name in ("REQUIRE", "ASSERT"):
            for formula, _ in roles[name]:
                if formula.op == "G":
                    return (
                        formula,
                        f"G on top of a {name} formula: strict semantics reads ASSERT W "
                        "!REQUIRE with the formulas as written, and (G a) W !r, a W !(G r) "
                        "are not the step-by-step a W !r the GR(1) game decides",
                        f"drop the G: a {name} formula holds in every step by itself",
                    )
    return None
