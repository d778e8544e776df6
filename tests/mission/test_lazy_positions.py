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


KEY = st.sampled_from(["a", "b", "rect", "c"])  # few names: repeated keys are common


@st.composite
def _block(draw: st.DrawFn, indent: int = 0, depth: int = 0) -> str:
    """A block mapping of drawn keys (repeats included) holding numbers, flow lists, flow
    mappings and, a few levels down, block mappings and block lists."""
    pad = " " * indent
    lines = []
    for _ in range(draw(st.integers(1, 3))):
        key = draw(KEY)
        kind = draw(st.integers(0, 4 if depth < 3 else 2))
        if kind == 0:
            lines.append(f"{pad}{key}: {draw(NUMBER)}\n")
        elif kind == 1:
            lines.append(f"{pad}{key}: [{', '.join(draw(st.lists(NUMBER, max_size=3)))}]\n")
        elif kind == 2:
            pairs = [f"{k}: {v}" for k, v in draw(st.lists(st.tuples(KEY, NUMBER), max_size=3))]
            lines.append(f"{pad}{key}: {{{', '.join(pairs)}}}\n")
        elif kind == 3:
            lines.append(f"{pad}{key}:\n" + draw(_block(indent + 2, depth + 1)))
        else:
            items = draw(st.lists(NUMBER, min_size=1, max_size=3))
            lines.append(f"{pad}{key}:\n" + "".join(f"{pad}- {v}\n" for v in items))
    return "".join(lines)


@given(_block())
def test_lazy_positions_of_keys_and_containers_at_every_depth(text: str) -> None:
    _agree(text)
    _agree("version: 1\nregions:\n" + "".join(f"  {line}\n" for line in text.splitlines()))


def test_a_valid_mission_is_read_once(monkeypatch: pytest.MonkeyPatch) -> None:
    # Lazy reading pays only when nothing asks for a position it skipped: a valid mission
    # (rect and polygon regions, a task, holes) is checked without reading it again.
    from tlmpc.mission.load import load_mission_text
    from tlmpc.mission.yamlpos import PositionedDocument

    def refuse(self: PositionedDocument) -> None:
        raise AssertionError("read again")

    monkeypatch.setattr(PositionedDocument, "_place_all", refuse)
    for file in sorted((ROOT / "specs").glob("*.yaml")):
        load_mission_text(file.read_text(encoding="utf-8"), str(file))


def test_a_repeated_key_below_the_top_level_is_placed_as_the_full_reading_places_it() -> None:
    text = "version: 1\nregions:\n  a: {rect: [0, 0, 1, 1]}\n  b: 1\n  a: 2\n"
    _, problems = load_positioned(text, "m.yaml", lazy=True)
    assert [p.code for p in problems] == ["Y002"]
    assert [p.format() for p in problems] == [
        p.format() for p in load_positioned(text, "m.yaml")[1]
    ]
    assert "line 3" in (problems[0].hint or "")


@pytest.mark.parametrize(
    "text",
    [
        "version: 1\nregions:\n  p: [[0, 0], [2, 0], {x: 1}, [2, 2]]\n",
        "version: 1\nregions:\n  p:\n  - - 0\n    - 0\n  - - 2\n    - 0\n  - [2, 2]\n",
        "regions:\n- - [1, 2]\n  - [3, 4]\n- {a: [5]}\n",
    ],
)
def test_lazy_positions_of_lists_of_containers(text: str) -> None:
    _agree(text)
