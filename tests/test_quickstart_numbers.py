"""The quickstart's walk through the stages quotes the numbers of the compile output it shows
(which tests/test_docs.py compares with what `tlmpc compile` prints)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _number(pattern: str, text: str) -> int:
    match = re.search(pattern, text)
    assert match is not None, pattern
    return int(match.group(1))


def test_the_stage_walk_quotes_the_shown_output() -> None:
    text = (ROOT / "docs" / "quickstart.md").read_text()
    walk = text[text.index("What happened, stage by stage") :]
    shown = text[: text.index("What happened, stage by stage")]
    assert _number(r"\((\d+)\s+triangles with angles", walk) == _number(
        r"abstraction .* triangles (\d+),", shown
    )
    assert _number(r"into a (\d+)-state Büchi automaton", walk) == _number(
        r"automaton .* states (\d+),", shown
    )
    assert _number(r"found the cheapest accepting run .*?: (\d+) triangles", walk) == _number(
        r"plan .* prefix (\d+),", shown
    )
