"""Phrase meanings checked against Spot: readers' formulas, safety never weakened, any order.

Spot is an independent oracle here: formulas are compared by language (``are_equivalent``) or
by inclusion, never by their text.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Callable

import pytest
from ci_oracles import import_oracle
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl import to_text
from tlmpc.tasks import avoid_scopes, compile_phrase

spot = import_oracle("spot")

GROUPS = {"exhibits": ["e1", "e2", "e3"]}

#: Held-out sentences and the formula a reader expects, written independently of the compiler.
HELD_OUT = [
    (
        "visit p2 then p3 then p4 then return to p1 while avoiding p2 and p3",
        "F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))",
    ),
    (
        "Visit area p2 then area p3 then area p4 and, finally, return to region p1 "
        "while avoiding areas p2 and p3",
        "F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))",
    ),
    (
        "visit pickup then dropoff then return to dock while avoiding forklift_lane",
        "G !forklift_lane & F(pickup & F(dropoff & F dock))",
    ),
    ("visit all exhibits then exit", "F(e1 & F exit) & F(e2 & F exit) & F(e3 & F exit)"),
    ("visit a, b and c then go to d", "F(a & F d) & F(b & F d) & F(c & F d)"),
    ("visit a and b, then visit c", "F(a & F c) & F(b & F c)"),
    ("go to kitchen while avoiding stairs", "F kitchen & G !stairs"),
    (
        "visit a then b then return to h while avoiding a, x",
        "G !x & F(a & F(b & (!a U h)))",
    ),
    ("avoid stairs until kitchen", "!stairs U kitchen"),
    # "visit a, b then c": some visit of c after both a and b, however far apart
    ("visit a, b then c", "F((a & F(b & F c)) | (b & F(a & F c)))"),
]


def _same_language(mine: str, expected: str) -> bool:
    return bool(spot.are_equivalent(spot.formula(mine), spot.formula(expected)))


@pytest.mark.parametrize(("phrase", "expected"), HELD_OUT)
def test_held_out_sentences_mean_what_readers_expect(phrase: str, expected: str) -> None:
    assert _same_language(to_text(compile_phrase(phrase, groups=GROUPS)), expected)


def test_the_papers_sentence_is_the_papers_formula_exactly() -> None:
    sentence = "visit p2 then p3 then p4 then return to p1 while avoiding p2 and p3"
    assert to_text(compile_phrase(sentence)) == "F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))"


def test_avoiding_the_region_being_left_starts_when_it_is_left() -> None:
    # a visited region avoided on the last leg may be the one the leg starts from
    automaton = spot.formula(
        to_text(compile_phrase("visit a then return to h while avoiding a"))
    ).translate()

    def accepts(word: str) -> bool:
        return bool(automaton.intersects(spot.parse_word(word).as_automaton()))

    assert accepts("!a&!h; a&!h; a&!h; !a&!h; !a&h; cycle{!a&!h}")
    assert accepts("!a&!h; a&!h; !a&!h; a&!h; !a&h; cycle{!a&!h}")  # after the last visit
    assert not accepts("!a&h; a&!h; cycle{!a&!h}")  # home only before a
    assert not accepts("a&!h; cycle{!a&!h}")  # never home


def test_avoiding_the_final_target_is_an_error() -> None:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase("visit a then b while avoiding b", file="m.yaml", line=4, col=5)
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == "T010"
    assert (diagnostic.line, diagnostic.col) == (4, 5 + len("visit a then b while avoiding "))


def _expand(formula: str) -> str:
    """The formula with each group's name read as any of its regions (as a mission does)."""
    for group, members in GROUPS.items():
        formula = re.sub(rf"\b{group}\b", "(" + " | ".join(members) + ")", formula)
    return formula


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        # `visit exhibits` is any one exhibit: e1 need not be visited, so it is avoided always
        ("visit exhibits then d while avoiding e1", "G !e1 & F((e1 | e2 | e3) & F d)"),
        ("visit d then exhibits while avoiding e1", "G !e1 & F(d & F(e1 | e2 | e3))"),
        ("visit exhibits while avoiding e1, e2", "G !e1 & G !e2 & F e3"),
        # a step inside the avoided group: visited, so avoided on the last leg
        ("visit e1 then d while avoiding exhibits", "F(e1 & (e1 U ((!e1 & !e2 & !e3) U d)))"),
        ("visit x then exhibits then d while avoiding x", "F(x & F((e1 | e2 | e3) & (!x U d)))"),
    ],
)
def test_a_group_step_is_any_one_of_its_regions(phrase: str, expected: str) -> None:
    mine = _expand(to_text(compile_phrase(phrase, groups=GROUPS)))
    assert _same_language(mine, expected), mine


@pytest.mark.parametrize(
    "phrase",
    [
        "visit d then all exhibits while avoiding e1",
        "visit d then e1 while avoiding exhibits",
        "visit d then exhibits while avoiding exhibits",
    ],
)
def test_avoiding_what_holds_every_final_target_is_an_error(phrase: str) -> None:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase(phrase, groups=GROUPS)
    assert [d.code for d in caught.value.diagnostics] == ["T010"]


SAME_CONDITION = "G(s & t -> F(!(s & t) | a)) & G(s & t & a -> (a W !(s & t)))"


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        ("when all of s and t, go to a and stay there while all of t and s", SAME_CONDITION),
        ("when all of s, t, go to a and stay there while all of t, s and t", SAME_CONDITION),
        (
            "when any of s, t, go to a and stay there while any of t, s",
            "G(s | t -> F(!(s | t) | a)) & G((s | t) & a -> (a W !(s | t)))",
        ),
    ],
)
def test_stay_there_while_the_same_condition_in_another_order(phrase: str, expected: str) -> None:
    assert _same_language(to_text(compile_phrase(phrase)), expected)


@pytest.mark.parametrize(
    "phrase",
    [
        "when all of s and t, go to a and stay there while any of t and s",
        "when s, go to a and stay there while all of s, t",
        "when any of s, t, go to a and stay there while any of s, u",
    ],
)
def test_stay_there_while_another_condition_is_t021(phrase: str) -> None:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase(phrase)
    assert [d.code for d in caught.value.diagnostics] == ["T021"]


def test_scopes_are_stated_in_words() -> None:
    scopes = avoid_scopes("visit p then q then return to h while avoiding p, lane")
    assert scopes == [
        "avoid lane: always (the phrase need not visit it)",
        "avoid p: on the last leg only, after the last visit, from q until h "
        "(the phrase visits it earlier)",
    ]
    assert avoid_scopes("avoid a, b") == ["avoid a and b: always"]
    assert avoid_scopes("visit a then b") == []


NAMES = ("r1", "r2", "r3", "r4", "r5", "r6")


@st.composite
def sequences(draw: st.DrawFn) -> tuple[str, list[list[str]], list[str], bool]:
    """A random sequence phrase: steps (sets of names), avoided names, return or not."""
    steps = draw(
        st.lists(
            st.lists(st.sampled_from(NAMES), min_size=1, max_size=2, unique=True),
            min_size=1,
            max_size=3,
        )
    )
    returns = len(steps) > 1 and len(steps[-1]) == 1 and draw(st.booleans())
    final = set(steps[-1])
    avoided = draw(
        st.lists(st.sampled_from([n for n in NAMES if n not in final]), max_size=2, unique=True)
    )
    if len(steps) == 1 and not avoided:
        avoided = []
    words = []
    for index, step in enumerate(steps):
        listing = step[0] if len(step) == 1 else ", ".join(step[:-1]) + " and " + step[-1]
        if index == 0:
            words.append(f"visit {listing}")
        elif index == len(steps) - 1 and returns:
            words.append(f"then return to {listing}")
        else:
            words.append(f"then {draw(st.sampled_from(['', 'go to ', 'visit ']))}{listing}")
    if avoided:
        words.append("while avoiding " + " and ".join(avoided))
    return " ".join(words), steps, avoided, returns


def _chains(steps: list[list[str]], last_leg: str | None) -> str:
    """Every chain s1 -> s2 -> ... -> sn, one per choice of a region in each step."""
    parts = []
    for chain in itertools.product(*steps):
        text = chain[-1] if last_leg is None else f"(({last_leg}) U {chain[-1]})"
        if last_leg is None:
            text = f"F {text}"
        for position in range(len(chain) - 2, -1, -1):
            name = chain[position]
            if last_leg is not None and position == len(chain) - 2 and f"!{name}" in last_leg:
                text = f"({name} U {text})"
            text = f"F({name} & {text})"
        parts.append(text)
    return " & ".join(parts)


@pytest.mark.slow
@given(sequences())
def test_sequences_never_weaken_a_visible_avoidance(
    case: tuple[str, list[list[str]], list[str], bool],
) -> None:
    phrase, steps, avoided, _ = case
    mine = spot.formula(to_text(compile_phrase(phrase)))
    visited = {name for step in steps for name in step}
    for name in avoided:
        if name not in visited:
            # the compiled task implies "never in name", from the first instant to forever
            assert spot.contains(spot.formula(f"G !{name}"), mine), (phrase, name)
    assert not mine.translate().is_empty(), phrase


@pytest.mark.slow
@given(sequences())
def test_sequences_are_every_chain_in_order(
    case: tuple[str, list[list[str]], list[str], bool],
) -> None:
    phrase, steps, avoided, _ = case
    visited = {name for step in steps for name in step}
    scoped = [n for n in avoided if n in visited]
    if scoped and (len(steps[-1]) > 1 or len(steps[-2]) > 1):
        # the last leg starts at the last visit of several regions, or several final
        # targets share one avoidance: not a chain property (the next test covers them)
        return
    last_leg = " & ".join(f"!{n}" for n in scoped) if scoped else None
    expected = _chains(steps, last_leg)
    always = [f"G !{n}" for n in avoided if n not in visited]
    expected = " & ".join([expected, *always])
    assert _same_language(to_text(compile_phrase(phrase)), expected), phrase


Word = tuple[list[frozenset[str]], list[frozenset[str]]]


def _holds_until(
    letters: list[frozenset[str]],
    start: int,
    keep: Callable[[int], bool],
    goal: Callable[[int], bool],
) -> bool:
    """``keep U goal`` at ``start`` of an unrolled word (long enough to hold a witness)."""
    for position in range(start, len(letters)):
        if goal(position):
            return True
        if not keep(position):
            return False
    return False


def _sequence_holds(word: Word, steps: list[list[str]], avoided: list[str]) -> bool:
    """The meaning of a sequence phrase on the lasso ``word``, from its definition in
    docs/task-phrases.md, without LTL: every region of a step visited after every region of
    the step before; names the phrase never visits avoided always; visited names avoided from
    the last intermediate visit (from when the robot leaves it, if it is avoided) until each
    final target."""
    prefix, cycle = word
    visited = {name for step in steps for name in step}
    if any(n in letter for n in avoided if n not in visited for letter in prefix + cycle):
        return False
    # every witness lies within this many positions (each step at most one more lap)
    letters = prefix + cycle * (2 * len(steps) + 4)
    done = 0  # the earliest instant by which the steps so far are complete, in order
    for step in steps[:-1]:
        starts = [done]
        for name in step:
            found = next((i for i in range(done, len(letters)) if name in letters[i]), None)
            if found is None:
                return False
            starts.append(found)
        done = max(starts)
    scoped = [n for n in avoided if n in visited]
    final = steps[-1]
    if not scoped:
        return all(any(name in x for x in letters[done:]) for name in final)

    def clear(position: int) -> bool:
        return not any(n in letters[position] for n in scoped)

    def inside(name: str) -> Callable[[int], bool]:
        return lambda position: name in letters[position]

    def leg(position: int) -> bool:
        return all(_holds_until(letters, position, clear, inside(f)) for f in final)

    before = steps[-2]
    for last in range(done, len(prefix) + len(cycle) * (len(steps) + 2)):
        for name in before:
            if name not in letters[last]:
                continue
            if name in scoped:
                ok = _holds_until(letters, last, inside(name), leg)
            else:
                ok = leg(last)
            if ok:
                return True
    return False


@st.composite
def words(draw: st.DrawFn, steps: list[list[str]], names: list[str]) -> Word:
    """A lasso over ``names``: half of them runs that go through the steps in some order with
    other regions (avoided ones among them) visited in between, half of them any letters."""
    one = st.sampled_from(names).map(lambda name: frozenset([name]))
    letter: st.SearchStrategy[frozenset[str]] = st.one_of(
        one, one, st.just(frozenset()), st.frozensets(st.sampled_from(names))
    )
    if draw(st.booleans()):
        prefix = draw(st.lists(letter, max_size=7))
    else:
        prefix = []
        for step in steps:
            for name in draw(st.permutations(step)):
                prefix += [*draw(st.lists(letter, max_size=2)), frozenset([name])]
    cycle = draw(st.lists(letter, min_size=1, max_size=3))
    return prefix, cycle


def _spot_word(word: Word, names: list[str]) -> str:
    def letter(x: frozenset[str]) -> str:
        return "&".join(n if n in x else f"!{n}" for n in names) or "1"

    prefix, cycle = word
    return "; ".join([*(letter(x) for x in prefix), "cycle{" + "; ".join(map(letter, cycle)) + "}"])


@pytest.mark.slow
@given(sequences(), st.data())
def test_sequences_mean_their_definition_on_words(
    case: tuple[str, list[list[str]], list[str], bool], data: st.DataObject
) -> None:
    phrase, steps, avoided, _ = case
    names = sorted({name for step in steps for name in step} | set(avoided))
    automaton = spot.formula(to_text(compile_phrase(phrase))).translate()
    for _ in range(20):
        word = data.draw(words(steps, names))
        accepted = bool(
            automaton.intersects(spot.parse_word(_spot_word(word, names)).as_automaton())
        )
        assert accepted == _sequence_holds(word, steps, avoided), (phrase, word)


def test_the_last_leg_starts_after_the_last_of_several_regions() -> None:
    # "visit a, b then c while avoiding a": a then b or b then a, then c without a again
    automaton = spot.formula(
        to_text(compile_phrase("visit a, b then c while avoiding a"))
    ).translate()

    def accepts(word: str) -> bool:
        return bool(automaton.intersects(spot.parse_word(word).as_automaton()))

    assert accepts("b&!a&!c; a&!b&!c; !a&!b&!c; c&!a&!b; cycle{!a&!b&!c}")
    assert accepts("a&!b&!c; b&!a&!c; c&!a&!b; cycle{!a&!b&!c}")
    assert not accepts("c&!a&!b; a&!b&!c; b&!a&!c; cycle{!a&!b&!c}")  # c only before
    earlier = spot.formula(
        to_text(compile_phrase("visit x then a, b then c while avoiding x"))
    ).translate()
    # x again after a and b, before c: whichever of them was last
    for word in ("x; a; b; x; c", "x; b; a; x; c"):
        letters = ["&".join(n if n == w else f"!{n}" for n in "xabc") for w in word.split("; ")]
        text = "; ".join(letters) + "; cycle{!x&!a&!b&!c}"
        assert not earlier.intersects(spot.parse_word(text).as_automaton()), word
    assert earlier.intersects(spot.parse_word("x; a; x; b; c; cycle{1}").as_automaton())
    # a whole group, then home: home once, after the last room, not after every room
    rooms = {"rooms": ["r1", "r2", "r3"]}
    phrase = "visit all rooms then return to h while avoiding rooms"
    # the group's name stands for any of its rooms (the mission expands it so)
    text = to_text(compile_phrase(phrase, groups=rooms)).replace("rooms", "(r1 | r2 | r3)")
    grouped = spot.formula(text)
    expected = spot.formula(
        "F(r1 & F(r2 & F(r3 & (r3 U ((!r1 & !r2 & !r3) U h))))) | "
        "F(r1 & F(r3 & F(r2 & (r2 U ((!r1 & !r2 & !r3) U h))))) | "
        "F(r2 & F(r1 & F(r3 & (r3 U ((!r1 & !r2 & !r3) U h))))) | "
        "F(r2 & F(r3 & F(r1 & (r1 U ((!r1 & !r2 & !r3) U h))))) | "
        "F(r3 & F(r1 & F(r2 & (r2 U ((!r1 & !r2 & !r3) U h))))) | "
        "F(r3 & F(r2 & F(r1 & (r1 U ((!r1 & !r2 & !r3) U h)))))"
    )
    assert spot.are_equivalent(grouped, expected)
