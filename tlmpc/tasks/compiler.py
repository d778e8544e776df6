"""Compile task phrases ("visit a then b while avoiding c") to LTL.

Each phrase is parsed with the grammar ``tasks.lark`` and lowered to one formula; the phrases
of a mission are conjoined.  Props keep spans pointing at the name inside the phrase, so the
mission loader can report an unknown region exactly where it is written.  The phrase → LTL
table is in docs/task-phrases.md (a test keeps it true).
"""

from __future__ import annotations

import difflib
import functools
import itertools
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from tlmpc.base.errors import Diagnostic, InvalidInputError, error
from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedGlobally,
    Eventually,
    Formula,
    Globally,
    Implies,
    Interval,
    Not,
    Or,
    Prop,
    Span,
    Until,
    WeakUntil,
    conjoin,
    disjoin,
)
from tlmpc.ltl.places import Place, placed
from tlmpc.tasks.phrases import KEYWORDS, Node, Word, parse_plain

if TYPE_CHECKING:
    from lark import Lark

#: The phrase forms, as shown to users when a phrase is not understood.
KNOWN_PHRASES = (
    "visit A",
    "visit A then B then C",
    "visit A then B then return to C",
    "visit A, B and C",
    "visit A, B and C then go to D",
    "visit A then B while avoiding C, D",
    "visit all GROUP",
    "visit all GROUP then A",
    "visit any GROUP",
    "visit A infinitely often",
    "avoid A, B",
    "never visit A",
    "avoid A until B",
    "patrol A, B",
    "stay in A",
    "eventually stay in A",
    "always stay in A",
    "whenever A, visit B",
    "if you sense S then visit A",
    "when S, go to A and stay there while S",
    "visit A infinitely often unless S",
    "never enter A while S",
    "if you sense S then do ACTION",
    "if you sense any of S, T then ...",
    "if you sense all of S, T then ...",
    "visit A within T s",
    "visit A at least every T s",
    "stay in A for at least T s",
    "never stay in A longer than T s",
    "after A, visit B within T s",
)
_LEADING_WORDS = (
    "visit",
    "avoid",
    "never",
    "patrol",
    "stay",
    "eventually",
    "always",
    "whenever",
    "if",
    "when",
    "after",
)


@functools.cache
def _parser() -> Lark:
    from importlib import resources

    from lark import Lark

    grammar = (resources.files("tlmpc.tasks") / "tasks.lark").read_text(encoding="utf-8")
    return Lark(grammar, parser="earley", ambiguity="resolve", propagate_positions=True)


def _from_lark(tree: Any) -> Node:
    """Lark's tree as the reader's :class:`Node` (names keep their line and column)."""
    from lark import Token

    children: list[Node | Word] = []
    for child in tree.children:
        if isinstance(child, Token):
            children.append(Word(str(child), child.line or 1, child.column or 1))
        else:
            children.append(_from_lark(child))
    return Node(str(tree.data), tuple(children))


class PhraseSyntaxError(Exception):
    """The phrase is not in the language; ``line`` and ``column`` (1-based, in the phrase) are
    where the parser stopped."""

    def __init__(self, column: int, line: int = 1) -> None:
        super().__init__(column)
        self.column = column
        self.line = line


@functools.lru_cache(maxsize=4096)  # trees are immutable; a check compiles each phrase thrice
def parse_tree(phrase: str) -> Node:
    """The parse tree of one phrase (rule ``start``); :class:`PhraseSyntaxError` when none.

    Plain phrases are read by :func:`tlmpc.tasks.phrases.parse_plain`; the rest (and every
    error) by the Earley parser of ``tasks.lark``, so the language and its messages are the
    grammar's.
    """
    plain = parse_plain(phrase)
    if plain is not None:
        return plain
    from lark.exceptions import LarkError

    try:
        return _from_lark(_parser().parse(phrase))
    except LarkError as exc:
        line = getattr(exc, "line", 1)
        column = getattr(exc, "column", 1)
        raise PhraseSyntaxError(
            column if isinstance(column, int) and column > 0 else 1,
            line if isinstance(line, int) and line > 0 else 1,
        ) from None


class _Lowering:
    """Lowers one phrase's parse tree to LTL, keeping name positions."""

    def __init__(
        self,
        groups: Mapping[str, Sequence[str]],
        file: str | None,
        line: int,
        col: int,
        kinds: NameKinds | None = None,
        place: Place | None = None,
    ) -> None:
        self.groups = groups
        self.kinds = kinds
        self.file = file
        self.line = line
        self.col = col
        #: where the phrase's character at a 1-based line and column is written in ``file``
        #: (a YAML string over several lines, quoted or a block); None: ``line``/``col`` + offset
        self.place = place
        self.problems: list[Diagnostic] = []
        #: each avoidance's scope in words, for ``tlmpc check --explain``
        self.scopes: list[str] = []

    def at(self, line: int, column: int) -> tuple[int, int]:
        """Where the phrase's character at ``line``:``column`` (1-based) is in the file."""
        return placed(line, column, (self.line, self.col), self.place)

    def _where(self, token: Word) -> tuple[int, int]:
        return self.at(token.line or 1, token.column or 1)

    def name(self, tree: Node) -> Prop:
        token = tree.children[0]
        assert isinstance(token, Word)
        line, col = self._where(token)
        return Prop(str(token), span=Span(line, col, line, col + len(token)))

    def names(self, tree: Node) -> list[Prop]:
        return [self.name(child) for child in tree.children if isinstance(child, Node)]

    def group(self, tree: Node) -> list[Formula]:
        prop = self.name(tree)
        members = self.groups.get(prop.name)
        if members is None:
            line, col = self._where(tree.children[0])  # type: ignore[arg-type]
            close = difflib.get_close_matches(prop.name, list(self.groups), n=1)
            self.problems.append(
                error(
                    "T002",
                    f"{prop.name!r} is not a group",
                    hint=(f"did you mean {close[0]!r}? " if close else "")
                    + "groups are declared under `groups:` in the mission",
                    file=self.file,
                    line=line,
                    col=col,
                )
            )
            return [prop]
        return [Prop(m, span=prop.span) for m in members]

    def lower(self, tree: Node) -> Formula:
        kind = tree.data
        children = [c for c in tree.children if isinstance(c, Node)]
        if kind == "visit_set":
            return conjoin([Eventually(p) for p in self.names(children[0])])
        if kind == "visit_all":
            return conjoin([Eventually(p) for p in self.group(children[0])])
        if kind == "visit_any":
            return Eventually(disjoin(self.group(children[0])))
        if kind == "visit_often":
            return conjoin([Globally(Eventually(p)) for p in self.names(children[0])])
        if kind == "visit_sequence":
            return self._sequence(children)
        if kind == "avoid":
            props = self.names(children[0])
            self._scope(props, "always")
            return conjoin([Globally(Not(p)) for p in props])
        if kind == "avoid_until":
            props = self.names(children[0])
            target = self.name(children[1])
            self._scope(props, f"until the first visit to {target.name}")
            return Until(conjoin([Not(p) for p in props]), target)
        if kind == "patrol":
            return conjoin([Globally(Eventually(p)) for p in self.names(children[0])])
        if kind == "stay":
            return Eventually(Globally(self.name(children[0])))
        if kind == "always_stay":
            return Globally(self.name(children[0]))
        if kind == "whenever":
            return Globally(Implies(self.name(children[0]), Eventually(self.name(children[1]))))
        if kind in _REACTIVE:
            return self._reactive(kind, children)
        if kind in _TIMED:
            seconds = _duration(tree)
            if math.isinf(seconds):
                # written finite, read unbounded: "within" would no longer bound anything
                token = tree.children[-1]
                assert isinstance(token, Word)
                line, col = self._where(token)
                self.problems.append(
                    error(
                        "T004",
                        f"the duration {str(token)!r} is too large for a float",
                        hint="write a duration below 1e308 s",
                        file=self.file,
                        line=line,
                        col=col,
                    )
                )
            return self._timed(kind, children, seconds)
        raise ValueError(f"unknown phrase kind {kind}")  # pragma: no cover - grammar is closed

    def _timed(self, kind: str, children: list[Node], seconds: float) -> Formula:
        window = Interval(0.0, seconds)
        if kind == "visit_within":
            return conjoin([BoundedEventually(p, window) for p in self.names(children[0])])
        if kind == "visit_every":
            return conjoin(
                [Globally(BoundedEventually(p, window)) for p in self.names(children[0])]
            )
        if kind == "stay_for":
            return Eventually(BoundedGlobally(self.name(children[0]), window))
        if kind == "stay_at_most":
            place = self.name(children[0])
            return Globally(Implies(place, BoundedEventually(Not(place), window)))
        trigger, goal = self.name(children[0]), self.name(children[1])
        return Globally(Implies(trigger, BoundedEventually(goal, window)))

    def _reactive(self, kind: str, children: list[Node]) -> Formula:
        """The reactive phrases (docs/task-phrases.md): each lowers to a conjunction of the
        GR(1) forms tlmpc synthesises (docs/semantics.md, reactive missions)."""
        if kind == "sense_visit":
            sensed = self._condition(children[0])
            goals = self._expect(self.names(children[1]), "region")
            return Globally(Implies(sensed, conjoin([Eventually(g) for g in goals])))
        if kind == "sense_do":
            sensed = self._condition(children[0])
            actions = self._expect(self.names(children[1]), "action")
            return Globally(Implies(sensed, conjoin(list(actions))))
        if kind == "often_unless":
            goals = self._expect(self.names(children[0]), "region")
            excused = self._condition(children[1])
            return conjoin([Globally(Eventually(Or((g, excused)))) for g in goals])
        if kind == "never_while":
            places = self._expect(self.names(children[0]), "region")
            sensed = self._condition(children[1])
            return conjoin(
                [
                    Globally(Implies(conjoin([sensed, Not(p)]), WeakUntil(Not(p), Not(sensed))))
                    for p in places
                ]
            )
        # sense_stay: reach the place while the condition lasts, then stay while it lasts
        sensed = self._condition(children[0])
        (place,) = self._expect([self.name(children[1])], "region")
        self._condition(children[2])  # its names are checked; the same condition as `when`
        if _condition_key(children[2]) != _condition_key(children[0]):
            self._report(
                "T021",
                children[2],
                "`stay there while` must name the same condition as `when`",
                "write the condition twice, e.g. `when alarm, go to shelter and stay there "
                "while alarm`",
            )
        return And(
            (
                Globally(Implies(sensed, Eventually(Or((Not(sensed), place))))),
                Globally(Implies(conjoin([sensed, place]), WeakUntil(place, Not(sensed)))),
            )
        )

    def _condition(self, tree: Node) -> Formula:
        """A sensor condition: one sensor, ``any of`` (or) or ``all of`` (and) several."""
        if tree.data == "condition":
            (sensor,) = self._expect([self.name(tree.children[0])], "sensor")  # type: ignore[arg-type]
            return sensor
        inner = next(c for c in tree.children if isinstance(c, Node))
        sensors = self._expect(self.names(inner), "sensor")
        return disjoin(list(sensors)) if tree.data == "any_condition" else conjoin(list(sensors))

    def _expect(self, props: list[Prop], kind: str) -> list[Prop]:
        """``props``, each reported (T020) when the mission declares it as another kind."""
        if self.kinds is not None:
            for prop in props:
                found = self.kinds.kind_of(prop.name)
                if (
                    found is not None
                    and found != kind
                    and not (kind == "region" and found == "group")
                ):
                    line, col = (prop.span.line, prop.span.col) if prop.span else (1, 1)
                    self.problems.append(
                        error(
                            "T020",
                            f"{prop.name!r} is {_a(found)}, not {_a(kind)}",
                            hint=_KIND_HINTS[kind],
                            file=self.file,
                            line=line,
                            col=col,
                        )
                    )
        return props

    def _report(self, code: str, tree: Node, message: str, hint: str) -> None:
        first = next(
            (w for w in _words(tree)),
            None,
        )
        line, col = self._where(first) if first is not None else (self.line, self.col)
        self.problems.append(error(code, message, hint=hint, file=self.file, line=line, col=col))

    def _avoided_names(self, avoiding: Node) -> list[Prop]:
        names_tree = next(c for c in avoiding.children if isinstance(c, Node))
        return self.names(names_tree)

    def _members(self, name: str) -> set[str]:
        """The regions a name stands for (a group stands for its members)."""
        return set(self.groups.get(name, (name,)))

    def _step(self, step: Node) -> list[Prop]:
        inner = next(c for c in step.children if isinstance(c, Node))
        if step.data == "all_step":
            return [p for p in self.group(inner) if isinstance(p, Prop)]
        if step.data == "return_step":
            return [self.name(inner)]
        return self.names(inner)

    def _sequence(self, children: list[Node]) -> Formula:
        """Steps S1 then S2 ... then Sn, each a set visited in any order after the previous set.

        ``Φ_k = ⋀_{s ∈ S_k} F(s & Φ_{k+1})``: each region of a step is visited after every
        region of the previous step (a later visit of a step's region serves all of it).

        ``while avoiding X`` never weakens into something a reader would not expect: a name the
        phrase need not visit is avoided always (``G !X``); a name the phrase must visit is
        avoided on the last leg — after the last intermediate visit, until the final target
        (the paper's "finally, return to p1 while avoiding p2 and p3").  Avoiding a final
        target is a contradiction and is reported (T010).
        """
        avoiding = children[-1] if children[-1].data == "avoiding" else None
        steps = [self._step(s) for s in (children[:-1] if avoiding is not None else children)]
        # the phrase must visit X when a step names something inside X (a group named as a
        # step is one of its members, any one: ``visit rooms`` need not visit r1)
        visited = [self._members(prop.name) for step in steps for prop in step]
        always: list[Prop] = []
        last_leg: list[Prop] = []
        if avoiding is not None:
            final = [self._members(p.name) for p in steps[-1]]
            for prop in self._avoided_names(avoiding):
                members = self._members(prop.name)
                if any(target <= members for target in final):
                    self._avoid_final(prop, steps[-1])
                elif any(step <= members for step in visited):
                    last_leg.append(prop)
                else:
                    always.append(prop)
        guard = conjoin([Not(p) for p in last_leg]) if last_leg else None
        leaving = {m for p in last_leg for m in self._members(p.name)}
        formula: Formula = conjoin(
            [Until(guard, s) if guard is not None else Eventually(s) for s in steps[-1]]
        )
        for index in range(len(steps) - 2, -1, -1):
            if index == len(steps) - 2 and guard is not None:
                formula = self._last_leg(steps[index], formula, leaving)
                continue
            formula = conjoin([Eventually(And((prop, formula))) for prop in steps[index]])
        self._scope(always, "always (the phrase need not visit {it})")
        if last_leg:
            before = steps[-2] if len(steps) > 1 else []
            start = "after the last visit, from " + _listing(before) if before else "from the start"
            self._scope(
                last_leg,
                f"on the last leg only, {start} until {_listing(steps[-1])} "
                "(the phrase visits {it} earlier)",
            )
        return conjoin([formula, *[Globally(Not(p)) for p in always]])

    def _last_leg(self, step: list[Prop], leg: Formula, leaving: set[str]) -> Formula:
        """Visit every region of ``step`` (in any order), then ``leg`` from the last visit.

        From a visit of an avoided region the leg starts when the robot leaves it.  With one
        region that is ``F(s & leg)``.  With several, the leg must start at a visit of the
        step made after all of them: ``⋀_s F(s & F P)`` with ``P = ⋁_s (s & leg)``.  (Each
        conjunct finds a ``P`` after its own region; the latest of those comes after all of
        them.  ``⋀_s F(s & leg)`` would demand the leg after *every* region's visit, so a
        region of the step visited after another would break the other's avoidance.)
        """
        starts: list[Formula] = []
        for prop in step:
            after = Until(prop, leg) if self._members(prop.name) & leaving else leg
            starts.append(And((prop, after)))
        if len(starts) == 1:
            return Eventually(starts[0])
        start = disjoin(starts)
        return conjoin([Eventually(And((prop, Eventually(start)))) for prop in step])

    def _avoid_final(self, prop: Prop, final: list[Prop]) -> None:
        line, col = (prop.span.line, prop.span.col) if prop.span else (self.line, self.col)
        self.problems.append(
            error(
                "T010",
                f"the phrase must reach {_listing(final)} while avoiding {prop.name!r}",
                hint="a region cannot be both the destination and avoided on the way; "
                "drop it from `while avoiding` or write a separate `avoid` phrase",
                file=self.file,
                line=line,
                col=col,
            )
        )

    def _scope(self, props: list[Prop], scope: str) -> None:
        if props:
            it = "it" if len(props) == 1 else "them"
            self.scopes.append(f"avoid {_listing(props)}: " + scope.replace("{it}", it))


_REACTIVE = frozenset({"sense_visit", "sense_stay", "often_unless", "never_while", "sense_do"})
_KIND_HINTS = {
    "sensor": "a condition after `sense`, `when`, `while` or `unless` names sensors, declared "
    "under `sensors:`",
    "region": "places to visit, enter or stay in are regions or groups",
    "action": "`do` names actions, declared under `actions:`",
}


@dataclass(frozen=True, slots=True)
class NameKinds:
    """What each name of a mission is: a region, a group, a sensor or an action."""

    regions: frozenset[str] = frozenset()
    groups: frozenset[str] = frozenset()
    sensors: frozenset[str] = frozenset()
    actions: frozenset[str] = frozenset()

    def kind_of(self, name: str) -> str | None:
        """``"region"``, ``"group"``, ``"sensor"``, ``"action"``, or None when unknown."""
        for kind, names in (
            ("region", self.regions),
            ("group", self.groups),
            ("sensor", self.sensors),
            ("action", self.actions),
        ):
            if name in names:
                return kind
        return None


def _words(tree: Node) -> list[Word]:
    found: list[Word] = []
    for child in tree.children:
        found.extend([child] if isinstance(child, Word) else _words(child))
    return found


#: The time-bounded phrase kinds (their last token is the duration).
_TIMED = frozenset({"visit_within", "visit_every", "stay_for", "stay_at_most", "after_within"})

_DURATION = re.compile(r"([0-9]+(?:\.[0-9]+)?)\s*([A-Za-z]+)")
_UNITS = {"s": 1.0, "sec": 1.0, "secs": 1.0, "second": 1.0, "seconds": 1.0}
_UNITS.update({"min": 60.0, "mins": 60.0, "minute": 60.0, "minutes": 60.0})


def _duration(tree: Node) -> float:
    """The seconds of a timed phrase's duration token (``30 s``, ``1.5 minutes``)."""
    found = _DURATION.fullmatch(str(tree.children[-1]))
    assert found is not None  # the grammar's DURATION
    return float(found.group(1)) * _UNITS[found.group(2).lower()]


def _condition_key(tree: Node) -> tuple[str, frozenset[str]]:
    """What a condition tests: ``any``/``all`` of a set of sensors (one sensor is either), so
    ``all of s and t`` and ``all of t, s`` are the same condition."""
    sensors = frozenset(str(w) for w in _words(tree))
    return ("one" if len(sensors) == 1 else tree.data, sensors)


def _a(kind: str) -> str:
    """``kind`` with its article: ``a sensor``, ``an action``."""
    return ("an " if kind[0] in "aeiou" else "a ") + kind


def _listing(props: Sequence[Prop]) -> str:
    names = [p.name for p in props]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


#: Words of the phrases besides :data:`KEYWORDS` that a did-you-mean may suggest.
_PHRASE_WORDS = KEYWORDS | {"within", "every", "least", "longer", "than", "after", "for"}
#: How close a misspelt word in a phrase must be to a phrase word to be suggested: closer than
#: difflib's default, since there a name (`dock`) stands where a word could (`do`).
_TYPO_CUTOFF = 0.75


def _unknown_phrase(
    phrase: str,
    file: str | None,
    line: int,
    col: int,
    stopped: tuple[int, int] = (1, 1),
) -> Diagnostic:
    """T001 at ``line``:``col``; ``stopped`` is where in the phrase the parser stopped (its
    line and column), whose word, when misspelt, the hint suggests a phrase word for."""
    first = phrase.strip().split(" ", 1)[0].lower() if phrase.strip() else ""
    close = difflib.get_close_matches(first, _LEADING_WORDS, n=1)
    if not close or close[0] == first:
        close = _misspelt_word(phrase, *stopped)
    hint = "known phrases: " + "; ".join(KNOWN_PHRASES)
    if close:
        hint = f"did you mean {close[0]!r}? " + hint
    return error(
        "T001",
        f"cannot understand the task phrase {phrase!r}",
        hint=hint,
        file=file,
        line=line,
        col=col,
    )


def _misspelt_word(phrase: str, line: int, column: int) -> list[str]:
    """The phrase word (at most one) the word at ``line``:``column`` of ``phrase`` is a
    misspelling of: `thne` for `then`, `avoidng` for `avoiding`; none for a phrase word."""
    lines = phrase.split("\n")
    if not 1 <= line <= len(lines):
        return []
    match = re.match(r"[A-Za-z_][A-Za-z0-9_]*", lines[line - 1][column - 1 :])
    if match is None or match.group().lower() in _PHRASE_WORDS:
        return []
    word = match.group().lower()
    return difflib.get_close_matches(word, sorted(_PHRASE_WORDS), n=1, cutoff=_TYPO_CUTOFF)


_IDENTIFIER = re.compile(r"(?<![A-Za-z0-9_])[A-Za-z_][A-Za-z0-9_]*")
#: Reserved words a phrase may name in its declared names before the rest is tried: each
#: subset of them is parsed once, so a phrase naming more is left to T001.
_MAX_RESERVED = 6


def _kind(name: str, groups: Mapping[str, Sequence[str]], kinds: NameKinds | None) -> str | None:
    found = kinds.kind_of(name) if kinds is not None else None
    return found or ("group" if name in groups else None)


def _reserved_names(
    phrase: str, groups: Mapping[str, Sequence[str]], kinds: NameKinds | None
) -> list[Word]:
    """The words of ``phrase`` that the mission declares as names but that the phrase
    grammar reserves as keywords (its ``NAME`` refuses them), with their places."""
    found: list[Word] = []
    for match in _IDENTIFIER.finditer(phrase):
        text = match.group()
        if text.lower() in KEYWORDS and _kind(text, groups, kinds) is not None:
            start = match.start()
            line = phrase.count("\n", 0, start) + 1
            found.append(Word(text, line, start - (phrase.rfind("\n", 0, start) + 1) + 1))
    return found


def _repair(phrase: str, words: list[Word]) -> list[Word]:
    """The fewest of ``words`` that, read as names, make ``phrase`` parse (none: none do).

    A reserved word a mission uses as a name may also stand in the phrase as the keyword
    (``visit then then b``): only the occurrences whose renaming makes the phrase parse are
    the ones meant as names."""
    if len(words) > _MAX_RESERVED:
        return []
    starts = [_place(phrase, w) for w in words]
    taken = {m.group().lower() for m in _IDENTIFIER.finditer(phrase)}
    stand_in = next(f"name{i}" for i in itertools.count() if f"name{i}" not in taken)
    for size in range(1, len(words) + 1):
        for chosen in itertools.combinations(range(len(words)), size):
            text = phrase
            for index in sorted(chosen, key=lambda i: -starts[i]):
                start = starts[index]
                text = text[:start] + stand_in + text[start + len(words[index]) :]
            try:
                parse_tree(text)
            except PhraseSyntaxError:
                continue
            return [words[i] for i in chosen]
    return []


def _place(phrase: str, word: Word) -> int:
    """The offset in ``phrase`` of ``word`` (its line and column are 1-based)."""
    offset = 0
    for _ in range(word.line - 1):
        offset = phrase.index("\n", offset) + 1
    return offset + word.column - 1


def _reserved(
    word: Word,
    lowering: _Lowering,
    groups: Mapping[str, Sequence[str]] | None,
    kinds: NameKinds | None,
) -> Diagnostic:
    kind = _kind(str(word), groups or {}, kinds) or "name"
    line, col = lowering._where(word)
    return error(
        "T003",
        f"{str(word)!r} is a {kind} of the mission, but task phrases read "
        f"`{word.lower()}` as a keyword, so no phrase can name it",
        # any longer word is a name (a keyword is a whole word): `region_then`
        hint=f"rename the {kind} (say `{kind}_{word}`), or state this part of the task "
        f"under `ltl:`, where {str(word)!r} is an ordinary name",
        file=lowering.file,
        line=line,
        col=col,
    )


def compile_phrase(
    phrase: str,
    *,
    groups: Mapping[str, Sequence[str]] | None = None,
    file: str | None = None,
    line: int = 1,
    col: int = 1,
    kinds: NameKinds | None = None,
    declared: NameKinds | None = None,
    place: Place | None = None,
) -> Formula:
    """Compile one phrase to LTL (raises :class:`InvalidInputError` with T-codes).

    With ``kinds`` (the mission's names by kind), a name used as the wrong kind — a region
    where a sensor belongs, say — is reported (T020).  ``declared`` (default ``kinds``) are
    the mission's names, to explain a phrase that fails because it names a word the phrases
    reserve (T003).  The phrase starts at ``line``:``col`` of ``file``; ``place``, when
    given, says where its character at a 1-based line and column is written (a YAML string
    over several lines, quoted or a block: :mod:`tlmpc.io.scalar_places`)."""
    return _compile(
        phrase,
        groups=groups,
        file=file,
        line=line,
        col=col,
        kinds=kinds,
        declared=declared,
        place=place,
    )[0]


def avoid_scopes(phrase: str, *, groups: Mapping[str, Sequence[str]] | None = None) -> list[str]:
    """Each avoidance in ``phrase`` with its scope in words (``avoid c: always``)."""
    return _compile(phrase, groups=groups, file=None, line=1, col=1)[1]


def _compile(
    phrase: str,
    *,
    groups: Mapping[str, Sequence[str]] | None,
    file: str | None,
    line: int,
    col: int,
    kinds: NameKinds | None = None,
    declared: NameKinds | None = None,
    place: Place | None = None,
) -> tuple[Formula, list[str]]:
    if not isinstance(phrase, str) or not phrase.strip():
        raise InvalidInputError(
            error(
                "T001",
                "empty task phrase",
                hint="known phrases: " + "; ".join(KNOWN_PHRASES),
                file=file,
                line=line,
                col=col,
            )
        )
    lowering = _Lowering(groups or {}, file, line, col, kinds, place)
    try:
        tree = parse_tree(phrase)
    except PhraseSyntaxError as exc:
        known = declared or kinds
        words = _reserved_names(phrase, groups or {}, known)
        repaired = _repair(phrase, words)
        if repaired:
            found = [_reserved(w, lowering, groups, known) for w in repaired]
            raise InvalidInputError(found) from None
        problem = _unknown_phrase(
            phrase, file, *lowering.at(exc.line, exc.column), stopped=(exc.line, exc.column)
        )
        if words:
            names = ", ".join(sorted({repr(str(w)) for w in words}))
            note = f"note: {names} cannot be named in a task phrase (a keyword there); "
            problem = error(
                problem.code,
                problem.message,
                hint=note + (problem.hint or ""),
                file=file,
                line=problem.line,
                col=problem.col,
            )
        raise InvalidInputError(problem) from None
    formula = lowering.lower(tree.children[0])  # type: ignore[arg-type]
    if lowering.problems:
        raise InvalidInputError(lowering.problems)
    written = _written_size(formula)
    if written > MAX_PHRASE_NODES:
        raise InvalidInputError(
            error(
                "T005",
                f"the phrase means a formula of {written:,} operators and names written out "
                f"(at most {MAX_PHRASE_NODES:,}): each region of a step repeats the rest of "
                "the sequence",
                hint="use fewer steps or fewer regions per step (a group step such as "
                "`all rooms` counts each member), or split the task into several phrases",
                file=file,
                line=line,
                col=col,
            )
        )
    return formula, lowering.scopes


#: The most nodes a phrase's formula may have written out as a tree.  The sequence reading
#: shares each step's rest among the step's regions, but printing, checking and translating
#: the formula walk it as a tree, whose size multiplies by the regions of every step.
MAX_PHRASE_NODES = 50_000


def _written_size(formula: Formula) -> int:
    """The node count of ``formula`` as a tree, counted over its shared nodes once each."""
    sizes: dict[int, int] = {}
    # post-order without recursion: a phrase may nest a step per word
    stack: list[tuple[Formula, bool]] = [(formula, False)]
    while stack:
        node, expanded = stack.pop()
        if id(node) in sizes:
            continue
        if expanded:
            sizes[id(node)] = 1 + sum(sizes[id(child)] for child in node.children())
            continue
        stack.append((node, True))
        stack.extend((child, False) for child in node.children() if id(child) not in sizes)
    return sizes[id(formula)]


def compile_phrases(
    phrases: Sequence[str],
    *,
    groups: Mapping[str, Sequence[str]] | None = None,
    file: str | None = None,
    positions: Sequence[tuple[int, int]] | None = None,
    kinds: NameKinds | None = None,
    declared: NameKinds | None = None,
    places: Sequence[Place | None] | None = None,
) -> Formula:
    """Compile every phrase and conjoin them; report the problems of all phrases at once.

    Args:
        phrases: the task phrases.
        groups: group name -> member region names (for ``visit all/any GROUP``).
        file: the file name for diagnostics.
        positions: (line, col) where each phrase starts in ``file``.
        kinds: the mission's names by kind, to report a name used as the wrong kind.
        declared: the mission's names by kind (default ``kinds``), to report a phrase that
            names a word the phrases reserve as a keyword (T003).
        places: per phrase, None or where its character at a 1-based line and column is
            written in ``file`` (a YAML string over several lines, quoted or a block).
    """
    formulas: list[Formula] = []
    problems: list[Diagnostic] = []
    for index, phrase in enumerate(phrases):
        line, col = positions[index] if positions is not None else (1, 1)
        try:
            formulas.append(
                compile_phrase(
                    phrase,
                    groups=groups,
                    file=file,
                    line=line,
                    col=col,
                    kinds=kinds,
                    declared=declared,
                    place=places[index] if places is not None else None,
                )
            )
        except InvalidInputError as exc:
            problems.extend(exc.diagnostics)
    if problems:
        raise InvalidInputError(problems)
    return conjoin(formulas)
