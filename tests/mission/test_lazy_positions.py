"""Lazy reading (no positions recorded for plain numbers) answers every position question
exactly as the full reading does."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.mission.yamlpos import load_positioned

ROOT = Path(__file__).resolve().parents[2]
FILES = sorted((ROOT / "specs").glob("*.yaml")) + sorted((ROOT / "tests").rglob("*.yaml"))


def _agree(text: str) -> None:
    full, full_problems = load_positioned(text, "m.yaml")
    lazy, lazy_problems = load_positioned(text, "m.yaml", lazy=True)
    assert lazy_problems == full_problems
    assert (lazy is None) == (full is None)
    if lazy is None or full is None:
        return
    assert lazy.data == full.data
    paths = list(full.values) + [(*p, 99) for p in full.values] + [(*p, 0, 1) for p in full.values]
    for path in paths:
        assert lazy.value_at(path) == full.value_at(path), path
        assert lazy.key_at(path) == full.key_at(path), path


@pytest.mark.parametrize("file", FILES, ids=lambda f: str(f.relative_to(ROOT)))
def test_lazy_positions_equal_full_positions_on_every_mission(file: Path) -> None:
    _agree(file.read_text(encoding="utf-8", errors="replace"))


def test_lazy_reading_defers_number_positions_and_rereads_once() -> None:
    text = "regions:\n  a:\n    rect:\n    - 0.5\n    - 1\n    - 2.0\n    - 3\n"
    lazy, _ = load_positioned(text, "m.yaml", lazy=True)
    assert lazy is not None
    assert ("regions", "a", "rect") in lazy.unplaced
    assert ("regions", "a", "rect", 2) not in lazy.values
    assert lazy.value_at(("regions", "a", "rect", 2)) == (6, 7)
    assert lazy.reread is None  # read again once, then answered from the full positions


NUMBER = st.one_of(
    st.integers(-(10**6), 10**6).map(str),
    st.floats(-1e6, 1e6, allow_nan=False).map(lambda v: f"{v:.3f}"),
    st.sampled_from(["1e-6", ".inf", "0x1F", "1_000", "'2.5'", "null", "[1, 2]", "{a: 1}"]),
)


@given(
    st.lists(st.lists(NUMBER, min_size=0, max_size=5), min_size=1, max_size=4),
    st.booleans(),
)
def test_lazy_positions_on_drawn_lists(rows: list[list[str]], flow: bool) -> None:
    if flow:
        body = "".join(f"  r{i}: [{', '.join(row)}]\n" for i, row in enumerate(rows))
    else:
        body = "".join(
            f"  r{i}:\n" + "".join(f"  - {v}\n" for v in row) + ("  []\n" if not row else "")
            for i, row in enumerate(rows)
        )
    _agree("version: 1\nlists:\n" + body)
