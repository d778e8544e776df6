"""A fast recursive-descent reader of task phrases, equal to the Earley parser where it answers.

``tasks.lark`` stays the definition of the phrase language: it is parsed with lark's Earley
parser (dynamic lexer, ``ambiguity="resolve"``), which costs a tenth of a second to build on
every start and milliseconds per phrase.  Nearly every real phrase is made of words —
keywords and names; a keyword is a whole word there (the grammar's keywords end at a word's
end, so ``visitor`` is a name, never ``visit`` + ``or``) — where the grammar is unambiguous
and one token of look-ahead decides every choice.  :func:`parse_plain` reads exactly those
phrases and returns the tree the Earley parser would return; for anything else (an unusual
character, a time-bounded or reactive phrase, a phrase that does not parse) it returns
``None`` and the caller asks the Earley parser, which then also words every error message.
A differential test draws phrases from the whole grammar, with adversarial names, and checks
both parsers agree.
"""

from __future__ import annotations

import re
from dataclasses import dataclass


class Word(str):
    """A region or group name as written, with its 1-based line and column in the phrase."""

    line: int
    column: int

    def __new__(cls, text: str, line: int, column: int) -> Word:
        word = super().__new__(cls, text)
        word.line = line
        word.column = column
        return word


@dataclass(frozen=True, slots=True)
class Node:
    """A rule of ``tasks.lark`` with its children as lark keeps them (anonymous tokens dropped)."""

    data: str
    children: tuple[Node | Word, ...]


#: Words the grammar's NAME terminal refuses (``tasks.lark``), lower case.
KEYWORDS = frozenset(
    {
        "visit",
        "then",
        "and",
        "avoid",
        "avoiding",
        "never",
        "until",
        "patrol",
        "stay",
        "remain",
        "in",
        "at",
        "always",
        "eventually",
        "whenever",
        "return",
        "to",
        "while",
        "all",
        "any",
        "infinitely",
        "often",
        "finally",
        "reach",
        "if",
        "you",
        "sense",
        "see",
        "when",
        "there",
        "unless",
        "enter",
        "do",
        "of",
    }
)
#: ``one of``, ``come back`` and ``go to`` are keywords only as a pair of words.
_PAIR_SECOND = {"one": "of", "come": "back", "go": "to"}
_NOUNS = frozenset({"area", "areas", "region", "regions", "room", "rooms"})

_TOKEN = re.compile(r"[ \t\f\r\n]*(?:([A-Za-z_][A-Za-z0-9_]*)|(,)|(\.)[ \t\f\r\n]*\Z)")
_WORD, _COMMA = "w", ","


class _NotPlain(Exception):
    """The phrase is not one this reader decides: ask the Earley parser."""


@dataclass(frozen=True, slots=True)
class _Token:
    kind: str  # _WORD or _COMMA
    text: str
    lower: str
    start: int


def _tokens(phrase: str) -> list[_Token]:
    tokens: list[_Token] = []
    at, end = 0, len(phrase)
    while True:
        while at < end and phrase[at] in " \t\f\r\n":
            at += 1
        if at == end:
            return tokens
        match = _TOKEN.match(phrase, at)
        if match is None:
            raise _NotPlain
        if match.group(1) is not None:
            text = match.group(1)
            tokens.append(_Token(_WORD, text, text.lower(), match.start(1)))
        elif match.group(2) is not None:
            tokens.append(_Token(_COMMA, ",", ",", match.start(2)))
        else:
            return tokens  # the optional final "."
        at = match.end()


class _Reader:
    def __init__(self, phrase: str, tokens: list[_Token]) -> None:
        self.phrase = phrase
        self.tokens = tokens
        self.at = 0

    # -- tokens -------------------------------------------------------------------------
    def _word(self, offset: int = 0) -> str | None:
        index = self.at + offset
        if index < len(self.tokens) and self.tokens[index].kind == _WORD:
            return self.tokens[index].lower
        return None

    def _comma(self, offset: int = 0) -> bool:
        index = self.at + offset
        return index < len(self.tokens) and self.tokens[index].kind == _COMMA

    def _pair(self, first: str, offset: int = 0) -> bool:
        """``first`` and its partner word next (``go to``, ``one of``): two word tokens in a
        row have only whitespace between them, as the grammar's two-word keywords ask."""
        return self._word(offset) == first and self._word(offset + 1) == _PAIR_SECOND[first]

    def _take(self, *words: str) -> bool:
        if self._word() in words:
            self.at += 1
            return True
        return False

    def _expect(self, *words: str) -> None:
        if not self._take(*words):
            raise _NotPlain

    def _visit(self) -> bool:
        if self._take("visit", "reach"):
            return True
        if self._pair("go"):
            self.at += 2
            return True
        return False

    def _nameable(self, offset: int = 0) -> bool:
        word = self._word(offset)
        return word is not None and word not in KEYWORDS

    # -- rules --------------------------------------------------------------------------
    def name(self) -> Node:
        if self._word() in _NOUNS and self._nameable(1):
            self.at += 1
        if not self._nameable():
            raise _NotPlain
        token = self.tokens[self.at]
        self.at += 1
        line = self.phrase.count("\n", 0, token.start) + 1
        column = token.start - (self.phrase.rfind("\n", 0, token.start) + 1) + 1
        return Node("name", (Word(token.text, line, column),))

    def names(self) -> Node:
        found = [self.name()]
        while True:
            if self._comma() and self._word(1) == "and" and self._nameable(2):
                self.at += 2
            elif (self._comma() or self._word() == "and") and self._nameable(1):
                self.at += 1
            else:
                return Node("names", tuple(found))
            found.append(self.name())

    def then(self) -> bool:
        """The grammar's ``_THEN`` terminal, read as greedily as its regular expression."""
        start = self.at
        if self._comma():
            self.at += 1
        if self._take("and") and self._comma():
            self.at += 1
        if not self._take("then", "finally"):
            self.at = start
            return False
        if self._comma():
            self.at += 1
        if self._take("finally") and self._comma():
            self.at += 1
        return True

    def avoiding(self) -> Node | None:
        offset = 1 if self._comma() else 0
        if self._word(offset) != "while":
            return None
        self.at += offset + 1
        self._expect("avoiding")
        return Node("avoiding", (self.names(),))

    def step(self) -> Node:
        if self._take("all"):
            return Node("all_step", (self.name(),))
        return Node("step", (self.names(),))

    def sequence(self, first: Node) -> Node:
        steps: list[Node] = [first]
        while self.then():
            if self._take("return"):
                self._expect("to")
                steps.append(Node("return_step", (self.name(),)))
                break
            if self._pair("come"):
                self.at += 2
                self._expect("to")
                steps.append(Node("return_step", (self.name(),)))
                break
            self._visit()
            steps.append(self.step())
        avoiding = self.avoiding()
        if avoiding is not None:
            steps.append(avoiding)
        if len(steps) == 1:  # neither a later step nor an avoidance: not a sequence
            raise _NotPlain
        return Node("visit_sequence", tuple(steps))

    def visit(self) -> Node:
        if self._take("all"):
            group = self.name()
            if self.at == len(self.tokens):
                return Node("visit_all", (group,))
            return self.sequence(Node("all_step", (group,)))
        if self._take("any") or (self._pair("one") and self._skip(2)):
            return Node("visit_any", (self.name(),))
        names = self.names()
        if self.at == len(self.tokens):
            return Node("visit_set", (names,))
        if self._take("infinitely"):
            self._expect("often")
            return Node("visit_often", (names,))
        return self.sequence(Node("step", (names,)))

    def _skip(self, count: int) -> bool:
        self.at += count
        return True

    def phrase_(self) -> Node:
        if self._visit():
            return self.visit()
        if self._take("avoid"):
            names = self.names()
            if self._take("until"):
                return Node("avoid_until", (names, self.name()))
            return Node("avoid", (names,))
        if self._take("never"):
            if not self._visit():
                raise _NotPlain
            return Node("avoid", (self.names(),))
        if self._take("patrol"):
            return Node("patrol", (self.names(),))
        if self._take("always"):
            self._expect("stay", "remain")
            self._expect("in", "at")
            return Node("always_stay", (self.name(),))
        if self._take("eventually") or self._word() in ("stay", "remain"):
            self._expect("stay", "remain")
            self._expect("in", "at")
            return Node("stay", (self.name(),))
        if self._take("whenever"):
            trigger = self.name()
            if self._comma():
                self.at += 1
            if not self._visit():
                raise _NotPlain
            return Node("whenever", (trigger, self.name()))
        raise _NotPlain


def parse_plain(phrase: str) -> Node | None:
    """The phrase's tree (rule ``start``), or None when the Earley parser must decide."""
    try:
        tokens = _tokens(phrase)
        if not tokens:
            return None
        reader = _Reader(phrase, tokens)
        tree = reader.phrase_()
        if reader.at != len(tokens):
            return None
    except _NotPlain:
        return None
    return Node("start", (tree,))
