"""The planner's fallbacks leave no reference cycle through a frame.

`tlmpc compile` pauses Python's cyclic collector for the whole compilation (the stages create
almost no cycles; reference counting frees the rest).  An exception kept in a local of a frame
its own traceback holds is such a cycle, and the traceback's frames hold every product searched
on the way: under the paused collector they stay alive until the compile ends.  Example 1 under
a disturbance its triangles cannot reject goes through every rung of the ladder (failed plans
on triangles, the goal depths, the convex cells' refinement) before it plans on cells.
"""

from __future__ import annotations

import gc
import types
from collections.abc import Iterator
from pathlib import Path

import pytest

import tlmpc

EXAMPLE1 = Path(__file__).parents[2] / "specs" / "example1.yaml"


@pytest.fixture
def paused_collector() -> Iterator[None]:
    was_enabled = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        yield
    finally:
        gc.set_debug(0)
        gc.garbage.clear()
        if was_enabled:
            gc.enable()


def test_a_plan_through_every_rung_leaves_no_frame_in_a_cycle(
    tmp_path: Path, paused_collector: None
) -> None:
    text = EXAMPLE1.read_text(encoding="utf-8")
    disturbed = text.replace("max_speed: 1.0}", "max_speed: 1.0, disturbance: 0.5}")
    assert disturbed != text
    source = tmp_path / "example1.yaml"
    source.write_text(disturbed, encoding="utf-8")
    result = tlmpc.compile(source, until="plan")
    assert result.artifacts["witness.json"]["stats"].get("cells") is True
    gc.set_debug(gc.DEBUG_SAVEALL)
    gc.collect()
    frames = [o.f_code.co_qualname for o in gc.garbage if isinstance(o, types.FrameType)]
    assert frames == []
