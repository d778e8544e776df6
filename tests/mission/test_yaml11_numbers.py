"""A plain number YAML 1.1 reads in another base than Python reads the same characters in
(``010`` is octal 8, ``1:30`` is base 60, 90) is refused (Y011) at its place, with the decimal
spelling in the hint; every other number keeps the value YAML 1.1 and Python agree on."""

from __future__ import annotations

import io
import json
import random
from pathlib import Path

import pytest
import yaml

from tlmpc.cli import main

MISSION = """\
version: 1
name: numbers
workspace:
  boundary: {{rect: [0, 0, 1000000, 2000]}}
regions:
  a: {{rect: [1, 1, {number}, 1500]}}
robot: {{start: [0.5, 0.5]}}
task: [visit a]
"""
COLUMN = MISSION.splitlines()[5].index("{number}")  # 1-based, less the "{" of "{{"


def _python(text: str) -> float | None:
    """The number Python reads from ``text`` (decimal digits with leading zeros included), or
    None when Python reads no number there."""
    digits = text.replace("_", "")
    for read in (lambda t: int(t, 0), lambda t: int(t, 10), float):
        try:
            return read(digits)
        except ValueError:
            continue
    return None


def _numerals() -> list[str]:
    fixed = ["010", "+010", "-010", "0_10", "007", "00", "0", "1:30", "1:30.5", "2:05:00",
             "0x10", "0b101", "1_0", "10.", "010.5", "0100", "07_7", "1e+2", "1.0e+2"]  # fmt: skip
    rng = random.Random(11)
    drawn = []
    for _ in range(40):
        text = rng.choice(["", "0", "00", "1", "12"]) + "".join(
            rng.choice("0123456789_") for _ in range(rng.randint(1, 3))
        )
        if rng.random() < 0.3:
            text += ":" + str(rng.randint(0, 59)).zfill(2)
        drawn.append(rng.choice(["", "+"]) + text)
    return [numeral for numeral in fixed + drawn if _in_workspace(numeral)]


def _in_workspace(numeral: str) -> bool:
    """Whether YAML 1.1 reads a number from ``numeral`` that fits the mission's workspace
    (other texts are the schema's business, other numbers another diagnostic's)."""
    value = yaml.safe_load(numeral)
    return isinstance(value, int | float) and not isinstance(value, bool) and 1 < value <= 1e6


@pytest.mark.parametrize("numeral", _numerals())
def test_numbers_yaml_1_1_reads_in_another_base_are_refused(tmp_path: Path, numeral: str) -> None:
    yaml_value = yaml.safe_load(numeral)
    path = tmp_path / "m.yaml"
    path.write_text(MISSION.format(number=numeral))
    out = io.StringIO()
    code = main(["compile", str(path), "-o", str(tmp_path / "out"), "--until", "load",
                 "--json", "-q"], out=out, err=io.StringIO())  # fmt: skip
    found = [(d["code"], d["line"], d["col"]) for d in json.loads(out.getvalue())["diagnostics"]]
    if _python(numeral) == yaml_value:
        assert code == 0, found
        written = json.loads((tmp_path / "out" / "mission.json").read_text())
        assert written["regions"]["a"][1][0] == pytest.approx(float(yaml_value))
    else:
        assert found == [("Y011", 6, COLUMN)]
        # and check says the same, with the decimal reading in the hint
        out = io.StringIO()
        assert main(["check", str(path), "--json"], out=out, err=io.StringIO()) == 1
        (diagnostic,) = json.loads(out.getvalue())["diagnostics"]
        assert (diagnostic["code"], diagnostic["line"], diagnostic["col"]) == found[0]
        decimal = _python(numeral)
        if decimal is not None:
            assert str(decimal) in diagnostic["hint"]
