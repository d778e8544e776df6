"""A hint is printed once per run: the first diagnostic that has it shows it, later ones with
the same hint do not (a plan refused at ten corners, C032, gets one long hint, not ten); each
distinct hint is printed; the ``--json`` envelope keeps every diagnostic with its hint."""

from __future__ import annotations

import io
import json
from pathlib import Path

import yaml

from tlmpc.base.errors import error
from tlmpc.cli import main
from tlmpc.io.report import Reporter

ROOT = Path(__file__).resolve().parent.parent


def test_each_distinct_hint_is_printed_once_and_the_envelope_keeps_them_all() -> None:
    err = io.StringIO()
    reporter = Reporter(command="compile", json=True, out=io.StringIO(), err=err)
    reporter.diagnose(
        [
            error("C032", "corner one", hint="the long hint"),
            error("C032", "corner two", hint="the long hint"),
            error("C034", "a point", hint="another hint"),
            error("C032", "corner three", hint="the long hint"),
            error("U001", "no hint at all"),
        ]
    )
    reporter.diagnose([error("C032", "a later batch", hint="the long hint")])
    lines = err.getvalue().splitlines()
    assert [line for line in lines if line.startswith("  hint:")] == [
        "  hint: the long hint",
        "  hint: another hint",
    ]
    assert lines.index("  hint: the long hint") == 1  # right after the first that has it
    assert sum("error[" in line for line in lines) == 6
    envelope = json.loads(reporter.envelope(1, None))
    assert [d.get("hint") for d in envelope["diagnostics"]] == [
        "the long hint",
        "the long hint",
        "another hint",
        "the long hint",
        None,
        "the long hint",
    ]


def test_a_plan_refused_at_many_corners_prints_its_hint_once(tmp_path: Path) -> None:
    mission = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    mission["robot"]["disturbance"] = 0.7  # beyond every plan of Example 1's meshes
    path = tmp_path / "mission.yaml"
    path.write_text(yaml.safe_dump(mission))
    out, err = io.StringIO(), io.StringIO()
    code = main(["compile", str(path), "-o", str(tmp_path / "out"), "--json"], out=out, err=err)
    assert code == 1
    refused = [line for line in err.getvalue().splitlines() if "error[C032]" in line]
    assert len(refused) > 1
    hints = [line for line in err.getvalue().splitlines() if line.startswith("  hint:")]
    assert len(hints) == 1
    assert "the largest disturbance any plan on this mesh rejects" in hints[0]
    diagnostics = json.loads(out.getvalue())["diagnostics"]
    stated = [d for d in diagnostics if d["code"] == "C032"]
    assert len(stated) == len(refused)
    assert all(d["hint"] == hints[0].removeprefix("  hint: ") for d in stated)
