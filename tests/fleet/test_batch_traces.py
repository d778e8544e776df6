"""A trace.json in a batch is verified as ``tlmpc verify TRACE`` verifies it alone: against
its own task and map (it is self-contained), never read as a bag.

The oracle is the trace's geometry: a straight run along y = 1 from x = 0 to x = 9 enters the
hazard (x from 3.5 to 4.5) at x = 3.5, so `G !hazard` is violated there, at t = 3.5 s."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

from tlmpc.cli import main

HAZARD = [[3.5, -1.0], [4.5, -1.0], [4.5, 3.0], [3.5, 3.0]]
GOAL = [[8.0, 0.0], [10.0, 0.0], [10.0, 2.0], [8.0, 2.0]]
MISSION = """\
version: 1
name: m
workspace:
  boundary: {rect: [0, 0, 10, 10]}
regions:
  far: {rect: [6, 6, 8, 8]}
robot: {start: [1, 1], max_speed: 1.0}
ltl: "F far"
"""


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def _trace(ltl: str) -> dict[str, Any]:
    return {
        "format": "tlmpc.trace/1",
        "ltl": ltl,
        "regions": {"hazard": HAZARD, "goal": GOAL},
        "workspace": {"boundary": [[-1, -1], [11, -1], [11, 5], [-1, 5]]},
        "boundary": "right",
        "max_speed": 1.0,
        "points": [[float(t), float(t), 1.0] for t in range(10)],
        "loop_start": None,
    }


def test_a_trace_json_among_logs_is_verified_against_its_own_task(tmp_path: Path) -> None:
    (tmp_path / "m.yaml").write_text(MISSION)
    avoid = tmp_path / "avoid.json"
    avoid.write_text(json.dumps(_trace("G !hazard & F goal")))
    reach = tmp_path / "reach.json"
    reach.write_text(json.dumps(_trace("F goal")))
    log = tmp_path / "log.csv"
    log.write_text("t,x,y\n0,1,1\n1,2,2\n")
    results = tmp_path / "r.jsonl"
    code, _, err = run_cli(
        "verify", str(avoid), str(reach), str(log), "--mission", str(tmp_path / "m.yaml"),
        "--no-cache", "--results", str(results),
    )  # fmt: skip
    assert code == 1, err
    records = {r["log"]: r for r in map(json.loads, results.read_text().splitlines())}
    assert records[str(avoid)]["verdict"] == "violated"
    assert records[str(avoid)]["formula"] == "G !hazard & F goal"
    first = records[str(avoid)]["first_violation"]
    assert first["conjunct"] == "G !hazard"
    assert first["t"] == 3.5
    assert (first["x"], first["y"]) == (3.5, 1.0)
    assert records[str(avoid)]["mission"] is None  # its own task, no mission file
    assert records[str(log)]["mission"] == str(tmp_path / "m.yaml")
    assert records[str(reach)]["verdict"] == "satisfied"
    assert records[str(reach)]["samples"] == 10
    assert records[str(log)]["verdict"] == "inconclusive"  # the mission's F far
    # and each as `tlmpc verify TRACE` says alone
    for trace in (avoid, reach):
        alone = json.loads(run_cli("verify", str(trace), "--json")[1])["result"]
        assert records[str(trace)]["verdict"] == alone["verdict"]


def test_a_file_that_is_neither_is_refused_as_verify_refuses_it_alone(tmp_path: Path) -> None:
    (tmp_path / "m.yaml").write_text(MISSION)
    other = tmp_path / "notes.json"
    other.write_text("{}")
    results = tmp_path / "r.jsonl"
    code, _, _ = run_cli(
        "verify", str(other), str(other), "--mission", str(tmp_path / "m.yaml"), "--no-cache",
        "--results", str(results),
    )  # fmt: skip
    assert code == 2
    alone = json.loads(run_cli("verify", str(other), "--json")[1])["diagnostics"][0]["code"]
    for line in results.read_text().splitlines():
        assert json.loads(line)["error"]["code"] == alone == "V001"


REACTIVE = MISSION.replace('ltl: "F far"', "sensors: {alarm: null}\ntask: [visit far]")


def _traces(tmp_path: Path) -> tuple[Path, Path]:
    avoid = tmp_path / "avoid.json"
    avoid.write_text(json.dumps(_trace("G !hazard & F goal")))
    reach = tmp_path / "reach.json"
    reach.write_text(json.dumps(_trace("F goal")))
    return avoid, reach


def _verdicts(results: Path) -> dict[str, str]:
    return {r["log"]: r["verdict"] for r in map(json.loads, results.read_text().splitlines())}


def test_a_batch_of_traces_needs_no_mission(tmp_path: Path) -> None:
    avoid, reach = _traces(tmp_path)
    results = tmp_path / "r.jsonl"
    code, _, err = run_cli(
        "verify", str(avoid), str(reach), "--no-cache", "--results", str(results)
    )
    assert code == 1, err
    assert _verdicts(results) == {str(avoid): "violated", str(reach): "satisfied"}
    # a log among them still needs one
    log = tmp_path / "log.csv"
    log.write_text("t,x,y\n0,1,1\n1,2,2\n")
    code, _, err = run_cli("verify", str(avoid), str(log), "--no-cache")
    assert code == 2
    assert "error[V010]" in err


def test_no_mission_given_applies_to_a_trace(tmp_path: Path) -> None:
    avoid, reach = _traces(tmp_path)
    # a reactive mission (refused for logs in a batch) and a mapping without a rule for them
    (tmp_path / "reactive.yaml").write_text(REACTIVE)
    (tmp_path / "m.yaml").write_text(MISSION)
    (tmp_path / "map.yaml").write_text(
        "format: tlmpc.fleet-missions/1\nmissions:\n  - {logs: '*.csv', mission: m.yaml}\n"
    )
    for mission in ("reactive.yaml", "map.yaml"):
        results = tmp_path / f"{mission}.jsonl"
        code, _, err = run_cli(
            "verify", str(avoid), str(reach), "--mission", str(tmp_path / mission),
            "--no-cache", "--results", str(results),
        )  # fmt: skip
        assert code == 1, err
        assert _verdicts(results) == {str(avoid): "violated", str(reach): "satisfied"}
