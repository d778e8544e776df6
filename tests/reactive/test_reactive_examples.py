"""The shipped reactive missions give the answers docs/examples.md states."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from game_oracle import check_strategy
from test_reactive_realizability import _faces

from tlmpc.abstraction import build_abstraction
from tlmpc.mission import load_mission
from tlmpc.reactive.synthesize import synthesize

ROOT = Path(__file__).resolve().parents[2]
ROW = re.compile(
    r"^\| \[(?P<name>[\w-]+)\]\(\.\./specs/reactive/[\w-]+\.yaml\)[^|]* \| [^|]+ \| "
    r"(?P<triangles>[\d,]+) \| (?P<faces>\d+) \| (?P<answer>\w+) \|$",
    re.MULTILINE,
)


def _rows() -> list[dict[str, str]]:
    return [m.groupdict() for m in ROW.finditer((ROOT / "docs" / "examples.md").read_text())]


def test_the_table_lists_every_reactive_spec() -> None:
    assert {r["name"] for r in _rows()} == {
        p.stem for p in (ROOT / "specs" / "reactive").glob("*.yaml")
    }


@pytest.mark.slow
@pytest.mark.parametrize("row", _rows(), ids=lambda r: r["name"])
def test_each_reactive_spec_gives_its_documented_answer(row: dict[str, str]) -> None:
    mission = load_mission(ROOT / "specs" / "reactive" / f"{row['name']}.yaml")
    abstraction = build_abstraction(mission)
    assert abstraction.num_triangles == int(row["triangles"].replace(",", ""))
    assert len(_faces(abstraction)[2]) == int(row["faces"])
    found = synthesize(mission, abstraction)
    assert found.realizable == (row["answer"] == "realizable")
    if found.strategy is not None and row["name"] == "guard":
        check_strategy(found.game.spec, found.strategy)
