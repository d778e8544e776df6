"""The stage walker holds each stage to its declaration: it provides exactly what it says."""

from __future__ import annotations

from pathlib import Path

import pytest

from tlmpc.pipeline.stages import (
    ABSTRACTION,
    MISSION,
    STAGES,
    Compilation,
    Stage,
    StageResult,
    provide,
    run_stages,
)

ROOT = Path(__file__).resolve().parents[2]
LOAD = next(stage for stage in STAGES if stage.name == "load")


def _load_also_providing_an_abstraction(c: Compilation) -> StageResult:
    from tlmpc.abstraction import build_abstraction

    result = LOAD.run(c)
    mesh = build_abstraction(result.products[MISSION])
    return StageResult(products={**result.products, **provide(ABSTRACTION, mesh)})


@pytest.mark.parametrize(
    ("stage", "said"),
    [
        (Stage(name="load", run=LOAD.run, provides=(MISSION, ABSTRACTION)), "missing: abstraction"),
        (
            Stage(name="load", run=_load_also_providing_an_abstraction, provides=(MISSION,)),
            "undeclared: abstraction",
        ),
    ],
)
def test_a_stage_that_breaks_its_declaration_is_stopped(stage: Stage, said: str) -> None:
    compilation = Compilation(source=ROOT / "specs" / "example1.yaml")
    with pytest.raises(RuntimeError, match=said):
        run_stages([stage], compilation)


def test_the_shipped_stages_keep_theirs() -> None:
    compilation = Compilation(source=ROOT / "specs" / "example1.yaml")
    result = run_stages(STAGES, compilation)
    assert MISSION in result.compilation.products
