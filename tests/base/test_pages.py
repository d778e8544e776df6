"""Plainly paged arrays: numpy's huge-page request is off inside the block and restored after
it (also after an error); values are numpy's own."""

from __future__ import annotations

import numpy as np
import pytest

from tlmpc.base.pages import _switch, plain_pages


def _current() -> bool:
    switch = _switch()
    assert switch is not None
    previous = switch(True)
    switch(previous)
    return previous


@pytest.mark.parametrize("setting", [True, False])
def test_the_request_is_off_inside_and_restored_after(setting: bool) -> None:
    switch = _switch()
    assert switch is not None
    before = switch(setting)
    try:
        with plain_pages():
            assert _current() is False
            array = np.full(1 << 20, np.inf)  # 8 MiB: above numpy's 4 MiB threshold
        assert _current() is setting
        assert bool(np.isinf(array).all())
        with pytest.raises(RuntimeError), plain_pages():
            raise RuntimeError("inside")
        assert _current() is setting
    finally:
        switch(before)


def test_stages_run_on_plain_pages_and_the_request_comes_back() -> None:
    from pathlib import Path

    from tlmpc.pipeline.stages import Compilation, Stage, StageResult, run_stages

    seen: list[bool] = []

    def probe(_: Compilation) -> StageResult:
        seen.append(_current())
        return StageResult()

    switch = _switch()
    assert switch is not None
    before = switch(True)
    try:
        run_stages([Stage(name="probe", run=probe)], Compilation(source=Path("mission.yaml")))
        assert seen == [False]
        assert _current() is True
    finally:
        switch(before)
