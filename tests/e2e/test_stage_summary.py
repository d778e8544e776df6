"""`tlmpc stage` keeps the folder's summary.json true to its artifacts: the plan, the verdict
and the stage's own record are the ones it wrote."""

from __future__ import annotations

import io
import json
from pathlib import Path

import tlmpc
from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]


def test_a_new_plan_is_the_summary_s_plan(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["compile", str(ROOT / "specs" / "example1.yaml"), "-o", str(out)]) == 0
    mission = json.loads((out / "mission.json").read_text())
    mission["options"]["cost"] = "hops"
    (out / "mission.json").write_text(json.dumps(mission))
    err = io.StringIO()
    assert main(["stage", "plan", str(out)], io.StringIO(), err) == 0, err.getvalue()
    witness = json.loads((out / "witness.json").read_text())
    summary = tlmpc.read_output(out).summary
    # the oracle is witness.json itself, which the compile's summary described before
    assert witness["metric"] == "hops"
    assert summary["plan"]["metric"] == "hops"
    assert summary["plan"]["cost"] == witness["cost"]
    assert summary["plan"]["prefix_length"] == len(witness["prefix"])
    plan_stage = next(stage for stage in summary["stages"] if stage["name"] == "plan")
    assert plan_stage["sizes"]["cost"] == round(witness["cost"], 6)
    assert [stage["name"] for stage in summary["stages"]].count("plan") == 1
