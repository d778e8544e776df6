"""The product's size is estimated before it is built, and too-large products are refused."""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from tlmpc.abstraction import build_abstraction
from tlmpc.automata import translate
from tlmpc.automata.degeneralize import degeneralize
from tlmpc.cli import main
from tlmpc.mission import load_mission
from tlmpc.planning import budget
from tlmpc.planning.budget import estimate_product
from tlmpc.planning.product import build_product

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("spec", ["example1", "example6", "patrol", "reach-avoid"])
def test_estimate_bounds_the_built_product(spec: str) -> None:
    mission = load_mission(ROOT / "specs" / f"{spec}.yaml")
    abstraction = build_abstraction(mission)
    automaton = translate(mission.formula, letters=abstraction.letters)
    estimate = estimate_product(abstraction, automaton)
    working = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    product = build_product(
        abstraction,
        working,
        allowed=np.ones(abstraction.num_triangles, dtype=bool),
        start_point=mission.robot.start,
        metric="length",
    )
    assert product.num_nodes <= estimate.nodes
    assert product.graph.nnz <= estimate.edges
    assert estimate.fits


def test_too_large_product_is_p040_before_building(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(budget, "MAX_PRODUCT_NODES", 1000)
    monkeypatch.setattr(budget, "MAX_GUIDED_NODES", 1000)

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("the product was built")

    monkeypatch.setattr(sys.modules["tlmpc.planning.plan"], "build_product", never)
    out, err = io.StringIO(), io.StringIO()
    spec = str(ROOT / "specs" / "example1.yaml")
    code = main(["compile", spec, "-o", str(tmp_path / "out"), "-q"], out=out, err=err)
    assert code == 2
    assert "error[P040]" in err.getvalue()
    assert not (tmp_path / "out").exists()


def test_product_beyond_the_build_budget_is_searched_as_expanded(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(budget, "MAX_PRODUCT_NODES", 1000)

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("the product was built")

    monkeypatch.setattr(sys.modules["tlmpc.planning.plan"], "build_product", never)
    out, err = io.StringIO(), io.StringIO()
    spec = str(ROOT / "specs" / "example1.yaml")
    code = main(["compile", spec, "-o", str(tmp_path / "out"), "-q"], out=out, err=err)
    assert code == 0, err.getvalue()
    witness = json.loads((tmp_path / "out" / "witness.json").read_text())
    assert witness["stats"]["search"] == "guided"
