"""`tlmpc monitor`: a JSON line whose t, x or y is not a number (M053) is placed at that
value's column, found by my own scan of the line (not the tool's JSON locator)."""

from __future__ import annotations

import io
import json
import random
import re
from pathlib import Path

from tlmpc.cli import main

MISSION = """\
version: 1
workspace: {boundary: {rect: [0, 0, 10, 10]}}
regions:
  a: {rect: [2, 2, 4, 4]}
robot: {start: [1, 1], max_speed: 100}
task: [visit a]
"""

NOT_NUMBERS = ['"1"', "true", "null", "[1]", '{"v": 1}', '"a,b: c"', "false"]


def _value_column(line: str, key: str) -> int:
    """The 1-based column of the last ``"key":`` value on ``line`` (JSON keeps the last of
    repeated keys), by scanning for the key outside strings myself."""
    found = -1
    inside = False
    i = 0
    while i < len(line):
        char = line[i]
        if inside:
            if char == "\\":
                i += 2
                continue
            if char == '"':
                inside = False
        elif char == '"':
            end = line.index('"', i + 1)
            rest = line[end + 1 :].lstrip(" ")
            if line[i + 1 : end] == key and rest.startswith(":"):
                after = end + 1 + (len(line[end + 1 :]) - len(rest)) + 1
                while line[after] == " ":
                    after += 1
                found = after + 1
            inside = True
        i += 1
    assert found > 0
    return found


def test_a_value_that_is_not_a_number_is_placed(tmp_path: Path) -> None:
    rng = random.Random(53)
    mission = tmp_path / "mission.yaml"
    mission.write_text(MISSION)
    log = tmp_path / "live.jsonl"
    for _ in range(40):
        values = {"t": "1.5", "x": "2", "y": "3"}
        key = rng.choice("txy")
        values[key] = rng.choice(NOT_NUMBERS)
        order = rng.sample("txy", 3)
        members = [f'"{k}":{" " * rng.randrange(3)}{values[k]}' for k in order]
        if rng.random() < 0.3:  # an earlier, valid copy of the key: the last one counts
            members.insert(0, f'"{key}": 0')
        line = " " * rng.randrange(3) + "{" + ("," + " " * rng.randrange(2)).join(members) + "}"
        assert json.loads(line)[key] == json.loads(values[key])
        first = '{"t": 0, "x": 1, "y": 1}'
        log.write_text(f"{first}\n{line}\n")
        err = io.StringIO()
        status = main(["monitor", "--mission", str(mission), str(log)], out=io.StringIO(), err=err)
        assert status == 2
        found = re.search(rf"{re.escape(str(log))}:(\d+):(\d+): error\[M053\]", err.getvalue())
        assert found is not None, err.getvalue()
        assert int(found.group(1)) == 2
        assert int(found.group(2)) == _value_column(line, key), (line, err.getvalue())
