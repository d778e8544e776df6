"""DOT output of automata whose proposition names hold quotes and backslashes.

Graphviz reads ``\\"`` inside a quoted string as a quote and ``\\\\`` as a backslash, so a name
ending in a backslash must not swallow the quote that closes the string.  The labels are read
back two ways: by Graphviz itself (``dot -Tjson``) when it is installed, and by a reading of
its quoted strings written here.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from collections.abc import Iterator

import pytest

from tlmpc.automata import degeneralize, to_dot, translate
from tlmpc.automata.model import Automaton
from tlmpc.ltl import parse_ltl
from tlmpc.ltl.ast import to_text

NAMES = ['x"y', "b\\", '\\"', "a\\nb", "plain"]
FORMULAS = [
    '"x\\"y" U "b\\\\"',
    'G F "\\\\\\"" & F "a\\\\nb"',
    '"b\\\\" R (plain | "x\\"y")',
]

_EDGE = re.compile(r'^  (\d+) -> (\d+) \[label="((?:[^"\\]|\\.)*)"\];$', re.M)
_NODE = re.compile(r'^  (\d+) \[shape=\w+, label="((?:[^"\\]|\\.)*)"\];$', re.M)


def _unescaped(text: str) -> str:
    """A DOT quoted string's text as Graphviz shows it: ``\\"`` and ``\\\\`` are one character."""
    return re.sub(r"\\(.)", lambda m: "\n" if m.group(1) == "n" else m.group(1), text)


def _expected_labels(automaton: Automaton) -> list[str]:
    labels = []
    for edge in automaton.edges:
        label = to_text(edge.guard)
        if edge.marks and not automaton.state_based:
            label += " {" + ",".join(str(m) for m in sorted(edge.marks)) + "}"
        labels.append(label)
    return labels


def _automata() -> Iterator[tuple[str, Automaton]]:
    for text in FORMULAS:
        automaton = translate(parse_ltl(text))
        yield text, automaton
        yield text + " (BA)", degeneralize(automaton)


@pytest.mark.parametrize(("text", "automaton"), list(_automata()))
def test_dot_quoted_strings_close_where_they_should(text: str, automaton: Automaton) -> None:
    dot = to_dot(automaton)
    edges = _EDGE.findall(dot)
    assert len(edges) == len(automaton.edges), text
    assert [_unescaped(label) for _, _, label in edges] == _expected_labels(automaton)
    nodes = _NODE.findall(dot)
    assert len(nodes) == automaton.num_states
    for state, label in nodes:
        assert _unescaped(label) == f"{state}\n{automaton.state_names[int(state)]}"


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz is not installed")
@pytest.mark.parametrize(("text", "automaton"), list(_automata()))
def test_graphviz_reads_the_labels_back(text: str, automaton: Automaton) -> None:
    run = subprocess.run(
        ["dot", "-Tjson"], input=to_dot(automaton), capture_output=True, text=True, check=False
    )
    assert run.returncode == 0, run.stderr
    graph = json.loads(run.stdout)
    init = next(node["_gvid"] for node in graph["objects"] if node["name"] == "init")
    labels = [edge["label"] for edge in graph["edges"] if edge["tail"] != init]
    # Graphviz keeps a label's escapes in -Tjson; undo them as it does when drawing
    assert sorted(_unescaped(label) for label in labels) == sorted(_expected_labels(automaton))


def test_names_of_the_formulas() -> None:
    names: set[str] = set()
    for text in FORMULAS:
        names |= parse_ltl(text).props()
    assert names == set(NAMES)
