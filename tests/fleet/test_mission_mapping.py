"""A mission mapping chooses by the log's path as given or its last parts, so its patterns mean
the same whichever way the logs' folder is named on the command line (docs/verify.md, "One
mission, or a mapping")."""

from __future__ import annotations

from pathlib import Path

import pytest

from tlmpc.fleet.batch import MissionRule, match

RULES = [
    MissionRule("husky*/*.csv", Path("patrol.yaml")),
    MissionRule("*.bag", Path("depot.yaml")),
    MissionRule("site/2026-*/*.csv", Path("site.yaml")),
]


@pytest.mark.parametrize(
    ("log", "mission"),
    [
        ("husky1/run.csv", "patrol.yaml"),  # run in logs/
        ("logs/husky1/run.csv", "patrol.yaml"),  # the documented `tlmpc verify logs/`
        ("./logs/husky2/run.csv", "patrol.yaml"),
        ("/data/robots/logs/husky3/day/run.csv", "patrol.yaml"),  # `*` crosses folders
        ("/data/logs/husky1.bag", "depot.yaml"),
        ("logs/site/2026-11-01/a.csv", "site.yaml"),
        ("logs/jackal/run.csv", None),
        ("logs/site/2025-11-01/a.csv", None),
        ("logs/myhusky1/run.csv", None),  # a folder's name is matched whole
    ],
)
def test_a_pattern_matches_the_last_parts_of_the_path(log: str, mission: str | None) -> None:
    found = match(RULES, Path(log))
    assert (None if found is None else str(found)) == mission
