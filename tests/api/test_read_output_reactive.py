"""`tlmpc.read_output` reads a reactive mission's output back: its summary.json (a
`synthesize` stage and the `reactive` record) matches the summary's schema."""

from __future__ import annotations

from pathlib import Path

import tlmpc
from tlmpc.io.outdir import write_artifacts
from tlmpc.io.schema_check import validation_errors

ROOT = Path(__file__).resolve().parents[2]


def test_a_reactive_output_is_read_back(tmp_path: Path) -> None:
    compiled = tlmpc.compile(ROOT / "specs" / "reactive" / "guard.yaml")
    summary = compiled.artifacts["summary.json"]
    assert "synthesize" in [stage["name"] for stage in summary["stages"]]
    assert summary["reactive"]["realizable"] is True
    assert validation_errors(summary, "summary") == []
    write_artifacts(tmp_path, compiled.artifacts)
    again = tlmpc.read_output(tmp_path)
    assert again.artifacts["strategy.json"] == compiled.artifacts["strategy.json"]
    assert again.summary["reactive"] == summary["reactive"]
