"""The per-compilation memo (tlmpc.base.memo): what one run of the stages reuses, and nothing
another run sees.

* The memo itself: a value per key while it is among the last ``keep`` asked for, its held
  object alive as long as it is kept, nothing remembered outside a run.
* Two compilations in one process: each partitions its own meshes (the second compile of the
  same mission builds as many partitions as the first, none taken over), writes the same
  bytes, and leaves no partition alive once it has returned; a compile of another mission in
  between changes nothing.
"""

from __future__ import annotations

import gc
import re
import weakref
from pathlib import Path
from typing import Any

import pytest
import yaml

import tlmpc
from tlmpc.base.memo import Memo, Slot, current_memo, memo_scope, recall
from tlmpc.io.artifacts import dumps
from tlmpc.planning import cells as cells_module
from tlmpc.planning.cells import Cells

ROOT = Path(__file__).resolve().parents[2]
_PARTITION = cells_module._partition
#: A timing in an artifact (masked: the only bytes two compiles may differ in).
TIMING = re.compile(r'("[a-z_]*seconds"\s*:\s*)-?[0-9.]+(?:e[-+]?[0-9]+)?')


class _Held:
    """An object a value is derived from (weakly referable, unlike a slotted IR object)."""


def test_a_value_is_built_once_per_key_while_kept() -> None:
    slot: Slot[list[int]] = Slot("test values", keep=2)
    memo = Memo()
    built: list[int] = []

    def build(n: int) -> list[int]:
        built.append(n)
        return [n]

    a, b, c = _Held(), _Held(), _Held()
    first = memo.recall(slot, id(a), a, lambda: build(1))
    assert memo.recall(slot, id(a), a, lambda: build(9)) is first
    memo.recall(slot, id(b), b, lambda: build(2))
    memo.recall(slot, id(a), a, lambda: build(9))  # a is now the most recent
    memo.recall(slot, id(c), c, lambda: build(3))  # pushes b out, not a
    assert memo.size(slot) == 2
    assert memo.recall(slot, id(a), a, lambda: build(9)) is first
    memo.recall(slot, id(b), b, lambda: build(4))
    assert built == [1, 2, 3, 4]


def test_the_held_object_lives_exactly_as_long_as_its_value_is_kept() -> None:
    slot: Slot[int] = Slot("test held", keep=1)
    memo = Memo()
    held = _Held()
    alive = weakref.ref(held)
    memo.recall(slot, id(held), held, lambda: 1)
    del held
    gc.collect()
    assert alive() is not None  # kept with its value: its id cannot be reused meanwhile
    other = _Held()
    memo.recall(slot, id(other), other, lambda: 2)
    gc.collect()
    assert alive() is None


def test_outside_a_run_nothing_is_remembered() -> None:
    slot: Slot[list[int]] = Slot("test outside", keep=4)
    held = _Held()
    assert current_memo() is None
    assert recall(slot, 1, held, lambda: [1]) is not recall(slot, 1, held, lambda: [1])
    with memo_scope() as memo:
        assert current_memo() is memo
        assert recall(slot, 1, held, lambda: [1]) is recall(slot, 1, held, lambda: [2])
        with memo_scope() as inner:  # a run inside a run has its own
            assert recall(slot, 1, held, lambda: [3]) == [3]
            assert current_memo() is inner
        assert current_memo() is memo
    assert current_memo() is None


def _disturbed(disturbance: float) -> dict[str, Any]:
    """Example 1 under a disturbance its triangles do not reject: the plan stage's cells'
    rung partitions several meshes."""
    mission = yaml.safe_load((ROOT / "specs" / "example1.yaml").read_text())
    mission["robot"]["disturbance"] = disturbance
    return dict(mission)


def _compile_counting(
    mission: dict[str, Any], monkeypatch: pytest.MonkeyPatch
) -> tuple[dict[str, str], list[weakref.ref[Cells]]]:
    built: list[weakref.ref[Cells]] = []

    def counting(abstraction: Any) -> Cells:
        cells = _PARTITION(abstraction)
        built.append(weakref.ref(cells))
        return cells

    monkeypatch.setattr(cells_module, "_partition", counting)
    compiled = tlmpc.compile(mission, until="control")
    texts = {
        name: TIMING.sub(r"\1T", dumps(document)) for name, document in compiled.artifacts.items()
    }
    return texts, built


def test_two_compilations_share_nothing_and_leave_nothing(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    mission = _disturbed(0.44)
    first, built_first = _compile_counting(mission, monkeypatch)
    assert "cells" in first["witness.json"]  # planned on convex cells
    gc.collect()
    assert built_first
    assert all(ref() is None for ref in built_first)  # every partition released
    assert current_memo() is None
    # another mission in between (other meshes), then the first again
    _compile_counting(_disturbed(0.36), monkeypatch)
    again, built_again = _compile_counting(mission, monkeypatch)
    assert len(built_again) == len(built_first)  # built anew, none taken over
    assert again == first
    gc.collect()
    assert all(ref() is None for ref in built_again)


def test_a_compile_partitions_each_mesh_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """Within one compilation the cells of a mesh are reused: the plan stage's mask, its
    searches, its witness check and the control stage's cell fields ask for them again."""
    asked: list[int] = []
    partition = cells_module.partition

    def asking(abstraction: Any) -> Cells:
        asked.append(id(abstraction))
        return partition(abstraction)

    monkeypatch.setattr(cells_module, "partition", asking)
    _, built = _compile_counting(_disturbed(0.44), monkeypatch)
    assert len(asked) > len(built)


def _regions_of_two_stages() -> tuple[object, object]:
    """The regions' documents of mission.json and abstraction.json, the two stages run one at
    a time (each its own run of the stages)."""
    from tlmpc.pipeline.stages import STAGES, Compilation, run_stages

    compilation = Compilation(source=ROOT / "specs" / "example1.yaml", text=None, figures=())
    artifacts: dict[str, Any] = {}
    for stage in STAGES[:2]:
        result = run_stages([stage], compilation)
        compilation = result.compilation
        artifacts.update(result.artifacts)
    return artifacts["mission.json"]["regions"], artifacts["abstraction.json"]["regions"]


def test_stages_run_one_at_a_time_share_an_open_memo() -> None:
    """A caller running the stages one at a time inside a memo (the memory bench) shares it as
    one compile does; without one, each run builds its own."""
    with memo_scope():
        mission_regions, mesh_regions = _regions_of_two_stages()
    assert mission_regions is mesh_regions
    mission_regions, mesh_regions = _regions_of_two_stages()
    assert mission_regions == mesh_regions
    assert mission_regions is not mesh_regions
