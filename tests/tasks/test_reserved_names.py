"""Names that task phrases reserve as keywords (T003): declared, usable in LTL, not in phrases."""

from __future__ import annotations

import re

import pytest

from tlmpc.base.errors import InvalidInputError
from tlmpc.mission.load import check_text
from tlmpc.tasks.compiler import _parser, compile_phrase


def _grammar_keywords() -> list[str]:
    """The words the grammar's NAME terminal refuses, read from the compiled grammar."""
    pattern = _parser().get_terminal("NAME").pattern.value
    match = re.match(r"\(\?!\(([a-z|]+)\)", pattern)
    assert match is not None, pattern
    return sorted(match.group(1).split("|"))


RESERVED = _grammar_keywords()


def _mission(name: str, task: str) -> str:
    return (
        "version: 1\nworkspace:\n  boundary: {rect: [0, 0, 10, 10]}\n"
        f"regions:\n  {name}: {{rect: [1, 1, 2, 2]}}\n  q: {{rect: [7, 7, 9, 9]}}\n"
        f"robot: {{start: [5, 5]}}\n{task}\n"
    )


PHRASES = ("visit {w}", "visit q then {w}", "avoid {w} until q", "visit q then {w} then q")


def test_the_grammar_reserves_words() -> None:
    assert len(RESERVED) > 20  # a pattern read wrongly would make the tests below vacuous
    assert "then" in RESERVED


@pytest.mark.parametrize("word", RESERVED)
def test_a_phrase_naming_a_reserved_word_is_t003_at_the_word(word: str) -> None:
    task = "task:\n" + "".join(f"  - {p.format(w=word)}\n" for p in PHRASES)
    text = _mission(word, task)
    problems = check_text(text, "m.yaml")
    assert [p.code for p in problems] == ["T003"] * len(PHRASES)
    lines = text.splitlines()
    for problem in problems:
        assert problem.line is not None
        assert problem.col is not None
        row = lines[problem.line - 1]
        assert row[problem.col - 1 :].startswith(word)
        assert not row[problem.col - 1 + len(word) :][:1].isalnum()
        assert repr(word) in problem.message
        assert problem.hint is not None
        assert "ltl:" in problem.hint
        renamed = re.search(r"say `([A-Za-z_0-9]+)`", problem.hint)
        assert renamed is not None
        # the suggested name and the LTL way both work
        fixed = "task:\n" + "".join(f"  - {p.format(w=renamed[1])}\n" for p in PHRASES)
        assert check_text(_mission(renamed[1], fixed), "m.yaml") == []
    assert check_text(_mission(word, f"ltl: F {word} & F q"), "m.yaml") == []


@pytest.mark.parametrize("word", RESERVED)
def test_a_reserved_name_no_phrase_uses_is_fine(word: str) -> None:
    assert check_text(_mission(word, "task: [visit q then q]"), "m.yaml") == []


def test_the_keyword_and_the_name_in_one_phrase() -> None:
    text = _mission("then", "task: [visit q then then]")
    (problem,) = check_text(text, "m.yaml")
    assert problem.code == "T003"
    assert problem.col == text.splitlines()[-1].rindex("then") + 1


def test_case_does_not_matter_and_groups_count() -> None:
    text = _mission("Then", "task: [visit Then]")
    assert [p.code for p in check_text(text, "m.yaml")] == ["T003"]
    grouped = _mission("a", "groups: {all: [a, q]}\ntask: [visit all all]")
    (problem,) = check_text(grouped, "m.yaml")
    assert problem.code == "T003"
    assert "group" in problem.message


def test_a_phrase_wrong_elsewhere_too_is_t001_with_a_note() -> None:
    (problem,) = check_text(_mission("then", "task: [visit then q q]"), "m.yaml")
    assert problem.code == "T001"
    assert problem.hint is not None
    assert "'then'" in problem.hint


@pytest.mark.parametrize("word", ["area", "within", "after", "every", "go", "one", "come"])
def test_words_that_are_not_reserved_name_regions(word: str) -> None:
    assert word not in RESERVED
    task = "task:\n" + "".join(f"  - {p.format(w=word)}\n" for p in PHRASES)
    assert check_text(_mission(word, task), "m.yaml") == []


def test_a_phrase_over_several_lines_is_t003_on_the_words_line() -> None:
    text = _mission("then", "task:\n  - |-\n    visit q then\n    then")
    (problem,) = check_text(text, "m.yaml")
    assert problem.code == "T003"
    assert problem.line == len(text.splitlines())


def test_without_a_mission_the_groups_are_the_names_known() -> None:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase("visit all all", groups={"all": ["a", "b"]})
    assert [d.code for d in caught.value.diagnostics] == ["T003"]
