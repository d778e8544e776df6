"""`tlmpc stage` refuses every stage a reactive mission does not have with U076.

Those stages read artifacts (automaton.json, witness.json, ...) that no compile of a reactive
mission writes, so "missing, run the earlier stages first" (U070) could never be followed;
the mission's kind is checked first, whether or not the stage reads mission.json.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tlmpc.io.outdir import write_artifacts
from tlmpc.pipeline.stages import (
    STAGES,
    MissingProductError,
    compile_mission,
    run_stage_from_artifacts,
)

ROOT = Path(__file__).resolve().parents[2]
STATIC_ONLY = [stage.name for stage in STAGES if "reactive" not in stage.worlds]


@pytest.fixture(scope="module")
def reactive_output(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("guard")
    whole = compile_mission(ROOT / "specs" / "reactive" / "guard.yaml")
    write_artifacts(out, whole.artifacts)
    return out


@pytest.mark.parametrize("name", STATIC_ONLY)
def test_a_static_stage_on_a_reactive_output_is_u076(reactive_output: Path, name: str) -> None:
    with pytest.raises(MissingProductError) as caught:
        run_stage_from_artifacts(name, reactive_output)
    (found,) = caught.value.diagnostics
    assert found.code == "U076"
    assert found.file == str(reactive_output / "mission.json")


def test_the_list_covers_the_stages_that_read_no_mission() -> None:
    assert {"plan", "control", "simulate", "verify", "plot"} <= set(STATIC_ONLY)
