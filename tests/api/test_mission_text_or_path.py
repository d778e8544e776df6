"""A mission string is YAML text or a path, decided by what it holds, never by asking the file
system about text: one-line missions of any length compile, a missing path is U001 whatever
its name, and every failure is a ``TlmpcError``.

The oracle of "the text is the mission" is the same mission given as a dict."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import yaml

import tlmpc


def _mission() -> dict[str, Any]:
    return {
        "version": 1,
        "name": "a notebook's mission, on one line",
        "workspace": {"boundary": {"rect": [0, 0, 10, 6]}, "holes": [{"rect": [4, 2, 6, 4]}]},
        "regions": {"dock": {"rect": [8, 4, 9.5, 5.5]}, "home": {"rect": [0.5, 0.5, 2, 2]}},
        "robot": {"start": [1, 1], "max_speed": 1.0},
        "task": ["visit dock then return to home"],
    }


ONE_LINE = {
    "json": json.dumps(_mission()),
    "flow yaml": yaml.safe_dump(_mission(), default_flow_style=True, width=10_000).strip(),
}


@pytest.mark.parametrize("style", sorted(ONE_LINE))
def test_a_one_line_mission_longer_than_a_file_name_is_text(style: str) -> None:
    text = ONE_LINE[style]
    assert "\n" not in text
    assert len(text) > 255  # longer than any file name may be
    assert tlmpc.check(text) == []
    from_text = tlmpc.compile(text, until="mission")
    from_dict = tlmpc.compile(_mission(), until="mission")
    assert from_text.formula == from_dict.formula
    assert from_text.artifacts["mission.json"] == from_dict.artifacts["mission.json"]


@pytest.mark.parametrize("path", ["C:/missing.yaml", "missing.yaml", "a" * 300, "d/" * 200])
@pytest.mark.parametrize("function", ["compile", "check"])
def test_a_missing_path_is_u001_whatever_its_name(path: str, function: str) -> None:
    with pytest.raises(tlmpc.UsageError) as caught:
        getattr(tlmpc, function)(path)
    assert caught.value.diagnostics[0].code == "U001"


@pytest.mark.parametrize(
    "text", ["x: " + "a" * 300, "{" + "a" * 300, '{"version": 1, "name": "' + "n" * 300]
)
def test_long_or_broken_one_line_text_fails_with_a_diagnostic(text: str) -> None:
    with pytest.raises(tlmpc.TlmpcError) as caught:
        tlmpc.compile(text)
    assert caught.value.diagnostics[0].code != "U001"  # read as text, not as a file name


def test_an_existing_file_named_like_a_mapping_is_read_as_a_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    Path("a: b.yaml").write_text(yaml.safe_dump(_mission()), encoding="utf-8")
    assert tlmpc.check("a: b.yaml") == []
