"""A ``.json`` mission reads its numbers as JSON does.

YAML 1.1 reads a plain ``1e-09`` as text (Y010 asks a YAML mission to write ``1.0e-09``), but
``json.dump`` writes exactly that for a float: a mission a program wrote as JSON must mean
what ``json.loads`` reads.  The oracle is Python's own ``json`` module.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.base.errors import InvalidInputError
from tlmpc.mission.load import load_mission


def _mission(radius: float, corner: float) -> dict[str, Any]:
    return {
        "version": 1,
        "workspace": {"boundary": [[corner, 0], [10, 0], [10, 10], [0, 10]]},
        "regions": {"a": {"rect": [1, 1, 2, 2]}},
        "robot": {"start": [5, 5], "max_speed": 1, "radius": radius},
        "task": ["visit a"],
    }


@settings(max_examples=40, deadline=None)
@given(
    radius=st.floats(1e-12, 0.5).map(lambda r: float(f"{r:.3e}")),
    corner=st.floats(1e-12, 0.5).map(lambda c: float(f"{c:.2e}")),
)
def test_a_json_mission_reads_numbers_as_json_does(
    tmp_path_factory: pytest.TempPathFactory, radius: float, corner: float
) -> None:
    text = json.dumps(_mission(radius, corner))
    path = tmp_path_factory.mktemp("json") / "mission.json"
    path.write_text(text)
    expected = json.loads(text)
    mission = load_mission(path)
    assert mission.robot.radius == expected["robot"]["radius"]
    assert mission.workspace.boundary[0][0] == expected["workspace"]["boundary"][0][0]


def test_the_same_text_as_yaml_keeps_asking_for_a_decimal_point(tmp_path: Path) -> None:
    text = json.dumps(_mission(1e-3, 0.0))
    assert "1e-03" in text or "0.001" in text
    path = tmp_path / "mission.yaml"
    path.write_text(text.replace("0.001", "1e-3"))
    with pytest.raises(InvalidInputError) as caught:
        load_mission(path)
    assert [d.code for d in caught.value.diagnostics] == ["Y010"]
