"""A reactive mission's core is deletion-minimal, not always the smallest, and the pages that
describe it say so.

The mission below has two cores: ``G F (b & !s)`` alone (the environment may keep ``s`` on) and
``G(s -> !a); G F a`` (the environment keeps ``s`` on and the robot may never reach ``a``).
Deletion drops the first part first (the other two still conflict) and ends at the second,
larger one: no part of it can be dropped, yet it is not the smallest.
"""

from __future__ import annotations

import json
from pathlib import Path

from tlmpc.abstraction import build_abstraction
from tlmpc.mission import load_mission_text
from tlmpc.reactive.synthesize import Synthesis, synthesize

ROOT = Path(__file__).resolve().parents[2]

MISSION = """\
version: 1
workspace:
  boundary: {{rect: [0, 0, 6, 4]}}
regions:
  a: {{rect: [0.5, 0.5, 1.5, 1.5]}}
  b: {{rect: [4.5, 0.5, 5.5, 1.5]}}
robot: {{start: [3, 1], max_speed: 1.0}}
sensors: {{s: null}}
ltl: '{ltl}'
"""


def _solve(ltl: str) -> Synthesis:
    mission = load_mission_text(MISSION.format(ltl=ltl), "core.yaml")
    return synthesize(mission, build_abstraction(mission))


def test_the_core_is_deletion_minimal_but_not_the_smallest() -> None:
    parts = ["G F (b & !s)", "G(s -> !a)", "G F a"]
    found = _solve(" & ".join(parts))
    assert found.core is not None
    core = [p.text for p in found.core]
    assert core == ["G(s -> !a)", "G F a"]
    for dropped in core:
        assert _solve(" & ".join(p for p in core if p != dropped)).realizable
    assert not _solve(parts[0]).realizable  # a core of one part: smaller


def test_the_pages_call_the_core_minimal_not_smallest() -> None:
    semantics = (ROOT / "docs" / "semantics.md").read_text()
    errors = (ROOT / "docs" / "errors.md").read_text()
    q110 = next(line for line in errors.splitlines() if line.startswith("| Q110 |"))
    schema = json.loads((ROOT / "schemas" / "counterstrategy.schema.json").read_text())
    for text in (semantics, q110, schema["description"]):
        assert "smallest set of task parts" not in text
    assert "no part can be dropped" in semantics
