"""The same mission gives the same bytes whatever the machine's load.

A mission whose task needs the automaton post-processing's optional reductions (overlapping
regions: many letters; a formula with nested releases and weak untils) is compiled twice in
fresh interpreters, once on an idle machine and once while two processes keep both cores busy,
and with different string-hash seeds (another process, another machine: the order in which a
set of strings iterates must decide nothing).  Every artifact must be byte for byte the same,
but for the fields that report time (every key ending in ``seconds``), which are masked.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

MISSION = """\
version: 1
name: determinism
workspace:
  boundary: {rect: [0, 0, 10, 6]}
regions:
  a: {rect: [0.5, 0.5, 6.0, 3.0]}
  b: {rect: [4.0, 0.5, 9.5, 3.0]}
  c: {rect: [3.0, 2.0, 7.0, 5.5]}
  d: {rect: [0.5, 4.0, 2.0, 5.5]}
robot: {start: [5.0, 5.0], max_speed: 0.5}
ltl: "((c R (G c W b)) W ((G a R (d U F(b R d))) R a))
  | (G F (a & b & c) & G F d & G (a -> F (b & !c)) & (!d U (a & c)))"
"""

#: Keeps one core busy until killed.
BURNER = "while True: pass"


def _compile(mission: Path, out: Path, hash_seed: int) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "tlmpc", "compile", str(mission), "-o", str(out), "-q"],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONHASHSEED": str(hash_seed)},
    )
    assert done.returncode == 0, done.stderr


def _masked(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: None if k.endswith("seconds") else _masked(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_masked(v) for v in value]
    return value


def _contents(out: Path) -> dict[str, Any]:
    """Every file of an output: JSON parsed with its timing fields masked, the rest as bytes."""
    contents: dict[str, Any] = {}
    for path in sorted(out.rglob("*")):
        if path.is_file():
            data = path.read_bytes()
            name = str(path.relative_to(out))
            contents[name] = _masked(json.loads(data)) if path.suffix == ".json" else data
    return contents


def test_masking_keeps_everything_but_the_timing_fields() -> None:
    value = {"seconds": 1.5, "stats": [{"solve_seconds": 2.0, "states": 4}], "cost": 3.0}
    assert _masked(value) == {
        "seconds": None,
        "stats": [{"solve_seconds": None, "states": 4}],
        "cost": 3.0,
    }


@pytest.mark.slow
def test_same_mission_same_artifacts_on_an_idle_and_a_busy_machine(tmp_path: Path) -> None:
    mission = tmp_path / "mission.yaml"
    mission.write_text(MISSION, encoding="utf-8")
    _compile(mission, tmp_path / "idle", hash_seed=1)
    burners = [subprocess.Popen([sys.executable, "-c", BURNER]) for _ in range(2)]
    try:
        _compile(mission, tmp_path / "busy", hash_seed=2)
    finally:
        for burner in burners:
            burner.kill()
            burner.wait()
    idle, busy = _contents(tmp_path / "idle"), _contents(tmp_path / "busy")
    assert {"automaton.hoa", "witness.json", "controllers.json"} <= idle.keys()
    assert idle.keys() == busy.keys()
    for name in idle:
        assert idle[name] == busy[name], name
