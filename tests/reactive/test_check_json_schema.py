"""`tlmpc check --json` on a reactive mission: the envelope is valid against the documented
output schema, with the GR(1) reading `--explain` prints under `gr1`."""

from __future__ import annotations

import io
import json
from pathlib import Path

import jsonschema

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]

REACTIVE = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 20, 20]}
regions:
  a: {rect: [1, 1, 3, 3]}
sensors: {s: null}
robot: {start: [10, 10]}
task:
  - visit a infinitely often unless s
"""


def test_the_envelope_of_a_reactive_mission_is_valid(tmp_path: Path) -> None:
    mission = tmp_path / "mission.yaml"
    mission.write_text(REACTIVE)
    out, err = io.StringIO(), io.StringIO()
    assert main(["check", "--json", str(mission)], out=out, err=err) == 0, err.getvalue()
    document = json.loads(out.getvalue())
    schema = json.loads((ROOT / "schemas" / "cli-output.schema.json").read_text())
    jsonschema.validate(document, schema)
    (entry,) = document["result"]["files"]
    assert entry["gr1"]
    assert all(isinstance(line, str) for line in entry["gr1"])
    assert any("a infinitely often unless s" in line for line in entry["gr1"])
