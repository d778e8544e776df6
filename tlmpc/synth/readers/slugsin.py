"""slugs' ``.slugsin`` format, read as slugs reads it.

Sections ``[INPUT] [OUTPUT] [ENV_INIT] [SYS_INIT] [ENV_TRANS] [SYS_TRANS] [ENV_LIVENESS]
[SYS_LIVENESS]``, one variable or one formula per line, ``#`` lines are comments.  Formulas
are in prefix notation over Boolean variables: ``! & | ^``, constants ``0 1``, ``x'`` for the
next value, and memory buffers ``$ N f0 ... f(N-1)`` whose value is the last formula, where
``? i`` inside the buffer recalls formula ``i`` (already read).  As in slugs, ENV_INIT may
mention inputs only, SYS_INIT current variables, ENV_TRANS no next outputs; liveness lines
may mention the next step (goals on transitions).  Every line is one part of the game.
"""

from __future__ import annotations

from collections.abc import Iterator

from tlmpc.synth.readers.source import Source
from tlmpc.synth.spec import (
    Atom,
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

#: slugs' sections: who owns each and what it holds (the structured format has the same)
SECTIONS: dict[str, tuple[Owner, str]] = {
    "[INPUT]": ("env", "vars"),
    "[OUTPUT]": ("sys", "vars"),
    "[ENV_INIT]": ("env", "init"),
    "[SYS_INIT]": ("sys", "init"),
    "[ENV_TRANS]": ("env", "safety"),
    "[SYS_TRANS]": ("sys", "safety"),
    "[ENV_LIVENESS]": ("env", "liveness"),
    "[SYS_LIVENESS]": ("sys", "liveness"),
}


class _Line:
    """The tokens of one formula line, with their offsets in the file."""

    def __init__(self, source: Source, start: int, text: str) -> None:
        self.source = source
        self.tokens: list[tuple[str, int]] = []
        offset = 0
        for word in text.split():
            offset = text.index(word, offset)
            self.tokens.append((word, start + offset))
            offset += len(word)
        self.pos = 0
        self.end = start + len(text)

    def next(self, what: str) -> tuple[str, int]:
        if self.pos == len(self.tokens):
            raise self.source.fail(
                "Q030",
                f"the formula ends early: expected {what}",
                self.end,
                "slugsin formulas are prefix: '& a b', '| ! a b', '$ 2 a & ? 0 b'",
            )
        token = self.tokens[self.pos]
        self.pos += 1
        return token


def section_lines(
    source: Source,
    text: str,
    *,
    code: str,
    unknown_hint: str,
    first_hint: str,
    other_tools: tuple[str, ...] = (),
) -> Iterator[tuple[Owner, str, str, int]]:
    """The lines of a slugs file (either format) under its sections: (owner, what the section
    holds, the stripped line, its offset), comments and blank lines skipped; ``code`` is the
    reader's code for an unknown section or a line before any, ``other_tools`` sections that
    belong to slugs' other synthesis modes."""
    section: tuple[Owner, str] | None = None
    offset = 0
    for raw in text.split("\n"):
        line_start = offset
        offset += len(raw) + 1
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        start = line_start + raw.index(stripped[0])
        if stripped.startswith("["):
            if stripped in other_tools:
                raise source.fail(
                    code,
                    f"the section {stripped} belongs to slugs' other synthesis modes",
                    start,
                    "tlmpc synth reads GR(1) games: declare the variables under [INPUT] or "
                    "[OUTPUT]",
                )
            if stripped not in SECTIONS:
                raise source.fail(code, f"unknown section {stripped!r}", start, unknown_hint)
            section = SECTIONS[stripped]
            continue
        if section is None:
            raise source.fail(code, "a line before any section", start, first_hint)
        yield (*section, stripped, start)


def parse_slugsin(
    text: str, *, file: str = "<input>", init_mode: InitMode = "forall_env_exists_sys"
) -> GameSpec:
    """Read a slugs specification."""
    source = Source(file, text)
    variables: dict[str, Variable] = {}
    parts: list[Part] = []
    for owner, what, stripped, start in section_lines(
        source,
        text,
        code="Q031",
        unknown_hint="slugsin sections are [INPUT] [OUTPUT] [ENV_INIT] [SYS_INIT] [ENV_TRANS] "
        "[SYS_TRANS] [ENV_LIVENESS] [SYS_LIVENESS]",
        first_hint="start the file with [INPUT] or [OUTPUT]",
    ):
        if what == "vars":
            name = stripped
            # a formula reads 0 and 1 as the constants, so such a variable could not be used
            malformed = any(ch.isspace() for ch in name) or name.endswith("'")
            if name in variables or malformed or name in ("0", "1"):
                problem = "is declared twice" if name in variables else "is not a variable name"
                raise source.fail(
                    "Q032",
                    f"{name!r} {problem}",
                    start,
                    "one variable per line, each name once, without spaces or a trailing ', "
                    "and not 0 or 1 (the constants)",
                )
            variables[name] = Variable(name, owner)
            continue
        kind: PartKind = what  # type: ignore[assignment]
        line = _Line(source, start, stripped)
        formula = _formula(line, [], variables, owner, kind)
        if line.pos != len(line.tokens):
            word, where = line.tokens[line.pos]
            raise source.fail(
                "Q030",
                f"stray text after the formula: {word!r}",
                where,
                "each line of a formula section holds exactly one prefix formula",
            )
        parts.append(Part(owner, kind, formula, source.location(start), stripped))
    return GameSpec(
        variables=tuple(variables.values()),
        parts=tuple(parts),
        init_mode=init_mode,
        source_format="slugsin",
        file=file,
    )


def _allowed(variable: Variable, primed: bool, owner: Owner, kind: PartKind) -> str | None:
    """Why slugs refuses the variable in this section, or None."""
    if kind == "init" and primed:
        return "initial conditions cannot mention next values"
    if kind == "init" and owner == "env" and variable.owner == "sys":
        return "ENV_INIT may mention inputs only"
    if kind == "safety" and owner == "env" and primed and variable.owner == "sys":
        return "ENV_TRANS cannot mention next outputs (the environment moves first)"
    return None


def _formula(
    line: _Line,
    memory: list[Expr],
    variables: dict[str, Variable],
    owner: Owner,
    kind: PartKind,
) -> Expr:
    word, where = line.next("an operator, a variable, 0 or 1")
    source = line.source
    if word in ("&", "|", "^"):
        left = _formula(line, memory, variables, owner, kind)
        right = _formula(line, memory, variables, owner, kind)
        return Nary({"&": "and", "|": "or", "^": "xor"}[word], (left, right))  # type: ignore[arg-type]
    if word == "!":
        return Not(_formula(line, memory, variables, owner, kind))
    if word in ("0", "1"):
        return Const(word == "1")
    if word in ("$", "?"):
        count_word, count_where = line.next("a number")
        if not (count_word.isascii() and count_word.isdigit()):
            raise source.fail(
                "Q033",
                f"expected a number after {word!r}, found {count_word!r}",
                count_where,
                "write '$ N' followed by N formulas, and '? i' to recall formula i",
            )
        # every formula takes a word of the line, so a number with more digits than the count
        # of its words (even one too long for int()) is too large for '$' and '?' alike
        too_large = len(line.tokens) + 1
        digits = count_word.lstrip("0")
        count = int(digits or "0") if len(digits) <= len(str(too_large)) else too_large
        shown = f"{word} {count_word}" if len(count_word) <= 20 else f"{word} {count_word[:20]}..."
        if word == "$":
            if count == 0:
                raise source.fail(
                    "Q033", "an empty memory buffer '$ 0'", where, "a buffer holds N >= 1 formulas"
                )
            words_left = len(line.tokens) - line.pos
            if count > words_left:
                raise source.fail(
                    "Q030",
                    f"the formula ends early: '{shown}' announces more formulas "
                    f"than the {words_left} word(s) after it on the line",
                    where,
                    "'$ N' is followed by exactly N formulas, the last one being its value",
                )
            buffer: list[Expr] = []
            while len(buffer) < count:
                buffer.append(_formula(line, buffer, variables, owner, kind))
            return buffer[-1]
        if count >= len(memory):
            raise source.fail(
                "Q033",
                f"'{shown}' recalls a formula that is not stored yet",
                where,
                "inside '$ N ...', '? i' may recall only the formulas before it",
            )
        return memory[count]
    primed = word.endswith("'")
    name = word[:-1] if primed else word
    if name not in variables:
        raise source.fail(
            "Q034",
            f"the variable {name!r} is not declared",
            where,
            "declare it under [INPUT] or [OUTPUT]",
        )
    variable = variables[name]
    reason = _allowed(variable, primed, owner, kind)
    if reason is not None:
        raise source.fail(
            "Q035",
            f"{word!r} is not allowed here: {reason}",
            where,
            "move the constraint to the section that may mention it (see docs/synthesis.md)",
        )
    return Atom(name, primed)
