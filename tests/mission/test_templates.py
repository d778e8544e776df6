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
from PIL import Image
from robot_data import image_from_free

from tlmpc.cli import main
from tlmpc.commands.new import TEMPLATES
from tlmpc.io.schema_check import validation_errors


def _run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("template", TEMPLATES)
@pytest.mark.parametrize("name", ["mission.yaml", "map.yaml", "my mission: v2.yaml"])
def test_every_template_is_a_mission_that_compiles(
    tmp_path: Path, template: str, name: str
) -> None:
    # a fresh folder: whatever the mission needs (the map template's map), `new` writes
    mission = tmp_path / name
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


def test_the_map_template_writes_its_map_beside_the_mission(tmp_path: Path) -> None:
    mission = tmp_path / "site.yaml"
    assert _run("new", "map", "-o", str(mission))[0] == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "site-map.pgm",
        "site-map.yaml",
        "site.yaml",
    ]
    assert yaml.safe_load(mission.read_text())["workspace"] == {"map": "site-map.yaml"}
    assert yaml.safe_load((tmp_path / "site-map.yaml").read_text())["image"] == "site-map.pgm"
    # the room: 40 x 40 cells, walls one cell thick, free inside
    with Image.open(tmp_path / "site-map.pgm") as image:
        pixels = np.asarray(image)
    assert pixels.shape == (40, 40)
    free = np.ones((40, 40), dtype=bool)
    free[[0, -1], :] = False
    free[:, [0, -1]] = False
    assert np.array_equal(pixels, image_from_free(free))


@pytest.mark.parametrize("existing", ["site-map.yaml", "site-map.pgm"])
def test_the_map_template_never_overwrites_a_map(tmp_path: Path, existing: str) -> None:
    (tmp_path / existing).write_text("my own map\n")
    code, _, err = _run("new", "map", "-o", str(tmp_path / "site.yaml"))
    assert code == 2
    assert "error[U094]" in err
    assert existing in err
    # nothing written: the refusal comes before the first file
    assert [p.name for p in tmp_path.iterdir()] == [existing]
    assert (tmp_path / existing).read_text() == "my own map\n"
