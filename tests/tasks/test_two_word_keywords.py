"""The two-word keywords (`go to`, `come back`, `one of`, `are sensing`) take any whitespace
between their words, as every other pair of words in a phrase does (`at  least`, `and then`):
a phrase broken over two lines of a YAML block means what it means on one line."""

from __future__ import annotations

import pytest

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl.printer import to_text
from tlmpc.tasks.compiler import _from_lark, _parser, compile_phrase
from tlmpc.tasks.phrases import parse_plain

GAPS = ["  ", "\t", "\n", " \n   ", "\r\n", "\f"]
GROUPS = {"rooms": ["r1", "r2", "r3"]}
#: each phrase with the LTL docs/task-phrases.md gives it
PHRASES = {
    "go{gap}to a": "F a",
    "visit a then come{gap}back to h": "F(a & F h)",
    "visit one{gap}of rooms": "F(r1 | r2 | r3)",
    "if you are{gap}sensing s then visit a": "G(s -> F a)",
}


@pytest.mark.parametrize("gap", GAPS)
@pytest.mark.parametrize("phrase", sorted(PHRASES))
def test_any_whitespace_joins_a_two_word_keyword(phrase: str, gap: str) -> None:
    text = phrase.format(gap=gap)
    assert to_text(compile_phrase(text, groups=GROUPS)) == PHRASES[phrase]
    plain = parse_plain(text)
    if plain is not None:  # the reader answers as the Earley parser does
        assert plain == _from_lark(_parser().parse(text))


@pytest.mark.parametrize(
    "text", ["goto a", "go tox", "go then b", "visit a then comeback to h", "visit a then come h"]
)
def test_the_words_stay_whole_words(text: str) -> None:
    with pytest.raises(InvalidInputError) as refused:
        compile_phrase(text, groups=GROUPS)
    assert [d.code for d in refused.value.diagnostics] == ["T001"]
