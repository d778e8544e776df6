"""The stages' results are equal when their content is, whatever their timings.

Two compilations of one mission give equal abstractions, witnesses and controllers though
their ``seconds`` differ; moving one vertex, one sample or one gain, or changing a size in the
stats, makes them unequal; an artifact read back equals the result it was written from.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tlmpc.abstraction.io import abstraction_from_json
from tlmpc.abstraction.model import Abstraction
from tlmpc.base.content import same_content
from tlmpc.control.io import controllers_from_json
from tlmpc.control.model import Controllers
from tlmpc.io.artifacts import dumps
from tlmpc.pipeline.stages import (
    ABSTRACTION,
    CONTROLLERS,
    WITNESS,
    Compilation,
    compile_mission,
)
from tlmpc.planning.io import witness_from_json
from tlmpc.planning.model import Witness

SPEC = Path(__file__).resolve().parents[2] / "specs" / "reach-avoid.yaml"


@pytest.fixture(scope="module")
def twice() -> tuple[Compilation, Compilation]:
    first = compile_mission(SPEC, until="control").compilation
    second = compile_mission(SPEC, until="control").compilation
    return first, second


def _timed(value: Any, seconds: float) -> Any:
    """``value`` with every timing field of its stats set to ``seconds``."""
    stats = {k: seconds if k.endswith("seconds") else v for k, v in value.stats.items()}
    return dataclasses.replace(value, stats=stats)


def test_two_compilations_give_equal_results(twice: tuple[Compilation, Compilation]) -> None:
    first, second = twice
    pairs: list[tuple[object, object]] = [
        (first.get(ABSTRACTION), second.get(ABSTRACTION)),
        (first.get(WITNESS), second.get(WITNESS)),
        (first.get(CONTROLLERS), second.get(CONTROLLERS)),
    ]
    for one, other in pairs:
        assert one == other
        assert hash(one) == hash(other)


def test_timings_do_not_count(twice: tuple[Compilation, Compilation]) -> None:
    abstraction, witness = twice[0].get(ABSTRACTION), twice[0].get(WITNESS)
    assert "seconds" in abstraction.stats
    assert "seconds" in witness.stats
    assert _timed(abstraction, 1e6) == abstraction
    assert _timed(witness, 1e6) == witness
    controllers = twice[0].get(CONTROLLERS)
    assert {"prepare_seconds", "solve_seconds"} <= controllers.stats.keys()
    assert _timed(controllers, 1e6) == controllers


def test_geometry_counts(twice: tuple[Compilation, Compilation]) -> None:
    abstraction: Abstraction = twice[0].get(ABSTRACTION)
    moved = abstraction.vertices.copy()
    moved[3, 0] += 1e-12
    assert dataclasses.replace(abstraction, vertices=moved) != abstraction
    relabelled = abstraction.letter_of.copy()
    relabelled[0] = (relabelled[0] + 1) % len(abstraction.letters)
    assert dataclasses.replace(abstraction, letter_of=relabelled) != abstraction
    narrower: Any = abstraction.triangles.astype(np.int32)  # same values, another dtype
    assert dataclasses.replace(abstraction, triangles=narrower) != abstraction
    controllers: Controllers = twice[0].get(CONTROLLERS)
    step = controllers.steps[0]
    gain = step.gain.copy()
    gain[0, 1] = -gain[0, 1] + 1.0
    changed = dataclasses.replace(step, gain=gain)
    assert changed != step
    steps = (changed, *controllers.steps[1:])
    assert dataclasses.replace(controllers, steps=steps) != controllers


def test_sizes_in_the_stats_count(twice: tuple[Compilation, Compilation]) -> None:
    witness: Witness = twice[0].get(WITNESS)
    sizes = [k for k, v in witness.stats.items() if isinstance(v, int) and k != "seconds"]
    assert sizes
    stats = {**witness.stats, sizes[0]: witness.stats[sizes[0]] + 1}
    assert dataclasses.replace(witness, stats=stats) != witness


def test_a_region_named_like_a_timing_is_content(twice: tuple[Compilation, Compilation]) -> None:
    abstraction: Abstraction = twice[0].get(ABSTRACTION)
    one = {**abstraction.regions, "wait_seconds": ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))}
    other = {**abstraction.regions, "wait_seconds": ((0.0, 0.0), (2.0, 0.0), (0.0, 2.0))}
    assert dataclasses.replace(abstraction, regions=one) != dataclasses.replace(
        abstraction, regions=other
    )


def test_arrays_by_shape_dtype_and_value() -> None:
    values = np.array([0.5, np.nan, -1.0])
    assert same_content(values, values.copy())  # NaN equals NaN here
    assert not same_content(values, values[:2])
    assert not same_content(values, values.astype(np.float32))
    assert not same_content(values, [0.5, np.nan, -1.0])
    assert same_content(np.arange(3), np.arange(3))
    assert not same_content(np.arange(3), np.arange(1, 4))
    assert same_content({"stats_seconds": 1.0}, {"stats_seconds": 2.0}, stats=True)
    assert not same_content({"stats_seconds": 1.0}, {"stats_seconds": 2.0})


def test_artifacts_read_back_to_equal_results() -> None:
    result = compile_mission(SPEC, until="control")
    compilation = result.compilation

    def document(name: str) -> Any:  # as written (large lists are arrays until then)
        return json.loads(dumps(result.artifacts[name]))

    assert abstraction_from_json(document("abstraction.json")) == compilation.get(ABSTRACTION)
    assert witness_from_json(document("witness.json")) == compilation.get(WITNESS)
    assert controllers_from_json(document("controllers.json")) == compilation.get(CONTROLLERS)
