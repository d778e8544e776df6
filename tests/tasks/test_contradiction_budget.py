"""The contradiction check's budget counts temporal operators (docs/cli.md: "up to 8 temporal
operators in all"); `->` and `<->` are connectives and do not use it up."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from tlmpc.cli import main

MISSION = """\
version: 1
workspace: {{boundary: {{rect: [0, 0, 10, 10]}}}}
regions:
  p: {{rect: [1, 1, 2, 2]}}
  q: {{rect: [3, 3, 4, 4]}}
  r: {{rect: [5, 5, 6, 6]}}
  s: {{rect: [7, 7, 8, 8]}}
robot: {{start: [9, 0.5]}}
ltl: "{ltl}"
"""

# Each is unsatisfiable by hand (and by Spot's ltl2tgba), with at most 8 temporal operators
# and several `->`/`<->`:
CONTRADICTIONS = [
    # 5 temporal operators: once p holds, p -> q -> r -> s -> !p
    "F p & G(p -> q) & G(q -> r) & G(r -> s) & G(s -> !p)",
    # 4: p and q always agree, q and r always agree, r never agrees with p
    "G(p <-> q) & G(q <-> r) & G(r <-> !p) & F s",
    # 6: q M (r & !p) needs a moment of q & r & !p; G(q <-> p) forbids q & !p
    "(q M (r & (p <-> false))) & G(q <-> p) & (G F s -> F G s) & F r",
]


@pytest.mark.parametrize("ltl", CONTRADICTIONS)
def test_a_contradiction_within_the_budget_is_found(tmp_path: Path, ltl: str) -> None:
    path = tmp_path / "mission.yaml"
    path.write_text(MISSION.format(ltl=ltl))
    err = io.StringIO()
    code = main(["check", str(path)], out=io.StringIO(), err=err)
    assert code == 1, err.getvalue()
    # at the formula's first character, after the opening quote
    assert f"{path}:9:7: error[L020]: the `ltl:` formula" in err.getvalue()


def test_the_budget_counts_temporal_operators_only() -> None:
    from tlmpc.ltl.parser import parse_ltl
    from tlmpc.tasks.contradiction import MAX_TEMPORAL_OPERATORS, contradictory

    # one group (every conjunct shares a region with another), 8 temporal operators and 7
    # connectives; unsatisfiable: once p holds, p -> q -> r -> !p
    within = (
        "F p & G(p -> q) & G(q -> r) & G(r -> !p) & G(p <-> q) & G(q <-> r) & F(q -> r)"
        " & F(r <-> p)"
    )
    assert sum(within.count(op) for op in ("F", "G")) == MAX_TEMPORAL_OPERATORS
    assert contradictory([parse_ltl(within)])
    # one more temporal operator: beyond the budget, left to compile
    assert not contradictory([parse_ltl(within + " & F q")])
