"""`tlmpc new`: every template is a valid mission that compiles, names the installed mission
schema for editors, and never overwrites a file."""

from __future__ import annotations

import io
import json
from pathlib import Path
from urllib.parse import unquote, urlparse

import numpy as np
import pytest
import yaml
from robot_data import image_from_free, write_map

from tlmpc.cli import main
from tlmpc.commands.new import TEMPLATES
from tlmpc.io.schema_check import validation_errors


def _run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("template", TEMPLATES)
def test_every_template_is_a_mission_that_compiles(tmp_path: Path, template: str) -> None:
    if template == "map":
        free = np.ones((40, 40), dtype=bool)
        free[[0, -1], :] = False
        free[:, [0, -1]] = False
        write_map(tmp_path, "map", image_from_free(free), resolution=0.1, origin=(-1.0, -1.0, 0.0))
    mission = tmp_path / f"mission-{template}.yaml"
    code, _, err = _run("new", template, "-o", str(mission))
    assert code == 0, err
    text = mission.read_text()
    first = text.splitlines()[0]
    assert first.startswith("# yaml-language-server: $schema=file://")
    schema = Path(unquote(urlparse(first.split("$schema=", 1)[1]).path))
    assert json.loads(schema.read_text())["$id"] == "urn:tlmpc:schema:mission:1"
    assert validation_errors(yaml.safe_load(text), "mission") == []
    assert _run("check", str(mission))[0] == 0
    code, _, err = _run("compile", str(mission), "-o", str(tmp_path / "out"), "-q")
    assert code == 0, err


def test_new_prints_without_o_and_never_overwrites(tmp_path: Path) -> None:
    code, text, _ = _run("new", "patrol")
    assert code == 0
    assert "patrol north, east, west" in text
    target = tmp_path / "mine.yaml"
    target.write_text("my own mission\n")
    code, _, err = _run("new", "patrol", "-o", str(target))
    assert code == 2
    assert "error[U094]" in err
    assert target.read_text() == "my own mission\n"
