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
