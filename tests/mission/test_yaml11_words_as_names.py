"""A name YAML 1.1 reads as a boolean or null (`yes`, `off`, `null`, `~`) where text is
expected — a group's member, a task phrase, the mission's name — is told as the word written,
with the hint to quote it; quoted, the same mission is valid."""

from __future__ import annotations

import pytest
import yaml

from tlmpc.mission import check_text

MISSION = """\
version: 1
name: NAME
workspace:
  boundary: {rect: [0, 0, 10, 10]}
regions:
  WORD: {rect: [1, 1, 2, 2]}
  b: {rect: [7, 7, 8, 8]}
groups: {g: [b, WORD]}
robot: {start: [5, 5]}
task: [visit all g]
"""

WORDS = ["yes", "No", "ON", "off", "True", "FALSE", "null", "Null"]


@pytest.mark.parametrize("word", WORDS)
def test_a_member_read_as_a_boolean_or_null_is_told_to_be_quoted(word: str) -> None:
    text = MISSION.replace("WORD", word).replace("NAME", "n")
    # the oracle: PyYAML's own reading of the word, as a list item, is no text
    assert not isinstance(yaml.safe_load(f"[{word}]")[0], str)
    (problem,) = check_text(text, "m.yaml")
    assert (problem.code, problem.line, problem.col) == ("S005", 8, 17)
    assert problem.message.startswith(f"$.groups.g[1]: {word} is read by YAML as ")
    assert "not of type" not in problem.message  # Python's True/None are not what was written
    assert problem.hint is not None
    assert problem.hint.startswith(f"quote it: '{word}'")
    quoted = text.replace(f"[b, {word}]", f"[b, '{word}']")
    assert check_text(quoted, "m.yaml") == []


def test_a_phrase_and_the_name_read_as_such_are_told_the_same_way() -> None:
    text = MISSION.replace("WORD", "a").replace("NAME", "off").replace("[visit all g]", "[Yes]")
    found = {(d.code, d.line, d.message, d.hint) for d in check_text(text, "m.yaml")}
    assert ("S005", 2, "$.name: off is read by YAML as the boolean false, not as text") in {
        f[:3] for f in found
    }
    assert ("S005", 10, "$.task[0]: Yes is read by YAML as the boolean true, not as text") in {
        f[:3] for f in found
    }


def test_an_empty_item_is_not_called_a_word() -> None:
    text = MISSION.replace("WORD", "a").replace("NAME", "n").replace("[b, a]", "[b, ]")
    text = text.replace("groups: {g: [b, ]}", "groups:\n  g:\n    - b\n    -")
    (problem,) = check_text(text, "m.yaml")
    assert problem.code == "S005"
    assert problem.message == "$.groups.g[1]: an empty value (null) is not text"
    (tilde,) = check_text(text.replace("    -\n", "    - ~\n"), "m.yaml")
    assert tilde.message == "$.groups.g[1]: ~ is read by YAML as null, not as text"
