"""``Formula`` is a closed union: every node class is in it, and mypy rejects a ``match``
over formulas that forgets a node kind (the ``assert_never`` at its end then type-checks no
more).  This is what keeps the evaluators, printers and rewrites complete when a node kind is
added."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import get_args

import pytest

from tlmpc.ltl import ast
from tlmpc.ltl.ast import Formula, Node

REPO = Path(__file__).resolve().parents[2]


def _concrete_node_class_names() -> set[str]:
    # By name: a slotted dataclass replaces its class, so the first class object may linger.
    found: set[str] = set()
    pending: list[type] = [Node]
    while pending:
        cls = pending.pop()
        subclasses: list[type] = cls.__subclasses__()
        for sub in subclasses:
            pending.append(sub)
            if not sub.__name__.startswith("_"):
                found.add(sub.__name__)
    return found


def test_the_union_lists_every_node_class() -> None:
    members = get_args(Formula)
    assert {cls.__name__ for cls in members} == _concrete_node_class_names()
    assert all(getattr(ast, cls.__name__) is cls for cls in members)


def test_every_member_is_a_frozen_node() -> None:
    for cls in get_args(Formula):
        assert issubclass(cls, Node)
        assert cls.__dataclass_params__.frozen


_MATCH_TEMPLATE = """
from typing import assert_never

from tlmpc.ltl.ast import (
    And, BoundedEventually, BoundedGlobally, BoundedUntil, Const, Equiv, Eventually, Formula,
    Globally, Implies, Not, Or, Prop, Release, StrongRelease, Until, WeakUntil,
)


def kind(formula: Formula) -> str:
    match formula:
        case Const() | Prop():
            return "atom"
        case Not() | And() | Or() | Implies() | Equiv():
            return "boolean"
        case Eventually() | Globally() | Until() | Release() | WeakUntil(){extra}:
            return "temporal"
        case BoundedEventually() | BoundedGlobally() | BoundedUntil():
            return "bounded"
        case _:
            assert_never(formula)
"""


def _mypy(tmp_path: Path, source: str) -> subprocess.CompletedProcess[str]:
    snippet = tmp_path / "snippet.py"
    snippet.write_text(textwrap.dedent(source))
    env = {**os.environ, "MYPYPATH": str(REPO)}
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "mypy",
            "--strict",
            "--no-error-summary",
            "--cache-dir",
            str(tmp_path / "cache"),
            "--config-file",
            os.devnull,
            str(snippet),
        ],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )


@pytest.mark.slow
def test_mypy_rejects_a_match_that_forgets_a_node_kind(tmp_path: Path) -> None:
    pytest.importorskip("mypy")
    complete = _mypy(tmp_path, _MATCH_TEMPLATE.format(extra=" | StrongRelease()"))
    assert complete.returncode == 0, complete.stdout + complete.stderr
    forgetful = _mypy(tmp_path, _MATCH_TEMPLATE.format(extra=""))
    assert forgetful.returncode == 1, forgetful.stdout + forgetful.stderr
    assert "assert_never" in forgetful.stdout
    assert "StrongRelease" in forgetful.stdout
