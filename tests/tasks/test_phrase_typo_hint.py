"""T001's did-you-mean names the phrase word a misspelt word stands for, wherever it is in the
phrase (docs/task-phrases.md: "the hint lists the known phrases and a did-you-mean"), at the
misspelt word's column."""

from __future__ import annotations

import pytest

from tlmpc.base.errors import InvalidInputError
from tlmpc.tasks import compile_phrase

# (phrase, the misspelt word, the word meant)
TYPOS = [
    ("visit a thne b", "thne", "then"),
    ("visit a then b while avoidng c", "avoidng", "avoiding"),
    ("visit a then b whle avoiding c", "whle", "while"),
    ("avoid a untill b", "untill", "until"),
    ("visit a infinitly often", "infinitly", "infinitely"),
    ("never stay in a lnger than 5 s", "lnger", "longer"),
    ("vist a then b", "vist", "visit"),
]


def _problem(phrase: str) -> tuple[str, int, str]:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase(phrase, file="m.yaml", line=3, col=7)
    (problem,) = caught.value.diagnostics
    assert problem.line == 3
    return problem.code, problem.col or 0, problem.hint or ""


@pytest.mark.parametrize(("phrase", "typo", "meant"), TYPOS)
def test_a_misspelt_word_gets_a_did_you_mean(phrase: str, typo: str, meant: str) -> None:
    code, col, hint = _problem(phrase)
    assert code == "T001"
    assert col == 7 + phrase.index(typo)
    assert hint.startswith(f"did you mean {meant!r}? known phrases:")


@pytest.mark.parametrize("phrase", ["visit a dock", "visit a b", "patrol a,, b", "visit a then"])
def test_a_name_where_no_word_is_meant_gets_no_suggestion(phrase: str) -> None:
    code, _, hint = _problem(phrase)
    assert code == "T001"
    assert hint.startswith("known phrases:")
