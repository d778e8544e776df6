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


# A character beyond U+FFFF, as ``json.dumps`` writes it by default: two UTF-16 escapes.
# Pieces that look like escapes once written (``\\ud83d``) mix with the wide characters.
_WIDE_TEXT = st.lists(
    st.one_of(
        st.characters(min_codepoint=0x10000, max_codepoint=0x10FFFF),
        st.sampled_from(["a", " ", '"', "\\", "u", "d83d", "\\ud83d", "\\ude00", "é"]),
    ),
    max_size=8,
).map("".join)


@settings(max_examples=60, deadline=None)
@given(name=_WIDE_TEXT)
def test_a_json_mission_reads_escaped_wide_characters_as_json_does(
    tmp_path_factory: pytest.TempPathFactory, name: str
) -> None:
    """The oracle: ``json.loads`` of the same text, and the same mission written with the
    characters themselves (no escapes), which the YAML reader takes as they are."""
    folder = tmp_path_factory.mktemp("wide")
    escaped = folder / "escaped.json"
    escaped.write_text(json.dumps({**_mission(0.1, 0.0), "name": name}))
    plain = folder / "plain.json"
    plain.write_text(json.dumps({**_mission(0.1, 0.0), "name": name}, ensure_ascii=False))
    expected = json.loads(escaped.read_text())["name"]
    try:
        plain_name = load_mission(plain).name
    except InvalidInputError:
        plain_name = None  # a character the reader refuses written plainly: not this property
    if plain_name is not None:
        assert plain_name == expected
        assert load_mission(escaped).name == expected


def test_what_follows_an_escaped_pair_on_its_line_keeps_its_column(tmp_path: Path) -> None:
    mission = {"name": "\U0001f600 \U0001f916", **_mission(0.1, 0.0)}
    mission["robot"]["max_speed"] = "fast"
    text = json.dumps(mission)
    assert text.index("\\ud83d\\ude00") < text.index('"fast"')
    assert "\n" not in text
    path = tmp_path / "mission.json"
    path.write_text(text)
    with pytest.raises(InvalidInputError) as caught:
        load_mission(path)
    (problem,) = caught.value.diagnostics
    assert (problem.line, problem.col) == (1, text.index('"fast"') + 1)


def test_an_escaped_backslash_before_u_is_no_escape(tmp_path: Path) -> None:
    """``"\\\\ud83d\\udc00"`` is a backslash, ``ud83d`` and a lone low surrogate to JSON: no
    pair to join, so the lone half is refused as any lone surrogate is, never read as a
    character that is not there."""
    text = json.dumps({**_mission(0.1, 0.0), "name": "\\ud83d\udc00"})
    assert '"\\\\ud83d\\udc00"' in text
    path = tmp_path / "mission.json"
    path.write_text(text)
    with pytest.raises(InvalidInputError) as caught:
        load_mission(path)
    assert [d.code for d in caught.value.diagnostics] == ["Y001"]
