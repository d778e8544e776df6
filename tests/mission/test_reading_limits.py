"""Bounded reading of missions: size, nesting, aliases, YAML 1.1 numbers, blank tasks."""

from __future__ import annotations

import math
import os
from pathlib import Path

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.base.errors import UsageError
from tlmpc.mission import load
from tlmpc.mission.geometry import check_layout, check_shape
from tlmpc.mission.load import check_text, inspect_file
from tlmpc.mission.shapes import shapely_polygon
from tlmpc.mission.yamlpos import MAX_DEPTH, MAX_NODES, load_positioned

VALID = """\
version: 1
workspace: {boundary: {rect: [0, 0, 4, 4]}}
regions: {a: {rect: [1, 1, 2, 2]}}
robot: {start: [3, 3], max_speed: 1.0}
task: [visit a]
"""


def codes(text: str) -> list[str]:
    return [d.code for d in check_text(text, "m.yaml")]


def test_the_valid_mission_is_valid() -> None:
    assert codes(VALID) == []


#: PyYAML's parsers: libyaml's (when built with it; 0.2.6 and later refuse 1,000 levels while
#: scanning ahead) and the pure-Python one.  The limits are ours on either.
LOADERS = [yaml.SafeLoader] + ([yaml.CSafeLoader] if yaml.__with_libyaml__ else [])


@pytest.fixture(params=LOADERS, ids=lambda loader: loader.__name__)
def loader(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> type:
    monkeypatch.setattr("tlmpc.mission.yamlpos._LOADER", request.param)
    return request.param  # type: ignore[no-any-return]


@pytest.mark.usefixtures("loader")
@pytest.mark.parametrize("depth", [MAX_DEPTH + 1, 999, 1_001, 30_000, 200_000])
def test_deep_flow_nesting_is_y003_not_a_crash(depth: int) -> None:
    assert codes("a: " + "[" * depth + "]" * depth + "\n") == ["Y003"]
    assert codes("a: " + "{a: " * depth + "1" + "}" * depth + "\n") == ["Y003"]
    problems = check_text("b: 1\nc:\n  - " + "[" * depth + "\n", "m.yaml")
    assert [(d.code, d.line) for d in problems] == [("Y003", 3)]


@pytest.mark.usefixtures("loader")
def test_nesting_within_the_limit_then_a_syntax_error_is_y001() -> None:
    depth = MAX_DEPTH - 1
    problems = check_text("a: " + "[" * depth + "]" * depth + "\nb: [1, 2\nc: 3\n", "m.yaml")
    assert [d.code for d in problems] == ["Y001"]
    assert codes("a: [1, 2]]\n") == ["Y001"]


@pytest.mark.usefixtures("loader")
def test_deep_block_nesting_is_y003() -> None:
    text = "".join(" " * i + f"k{i}:\n" for i in range(MAX_DEPTH + 5))
    assert codes(text) == ["Y003"]


def test_alias_bomb_stops_early() -> None:
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    for level in range(1, 12):
        refs = ", ".join([f"*a{level - 1}"] * 10)
        lines.append(f"a{level}: &a{level} [{refs}]")
    problems = check_text("\n".join(lines) + "\n")
    assert [d.code for d in problems] == ["Y003"]
    assert f"{MAX_NODES:,}" in problems[0].message


@pytest.mark.parametrize("lazy", [False, True])
@pytest.mark.parametrize("flow", [False, True])
def test_the_value_limit_counts_every_number_of_a_list(
    monkeypatch: pytest.MonkeyPatch, lazy: bool, flow: bool
) -> None:
    # The document's values: its mapping, the list, then n numbers (keys are not values).
    monkeypatch.setattr("tlmpc.mission.yamlpos.MAX_NODES", 50)
    for n, expected in ((48, []), (49, ["Y003"])):
        numbers = [str(i) if i % 2 else f"{i}.5" for i in range(n)]
        if flow:
            text = f"xs: [{', '.join(numbers)}]\n"
        else:
            text = "xs:\n" + "".join(f"- {v}\n" for v in numbers)
        doc, problems = load_positioned(text, "x", lazy=lazy)
        assert [d.code for d in problems] == expected, n
        assert (doc is None) == bool(expected)


def test_aliases_expand_to_shared_data_with_positions() -> None:
    doc, problems = load_positioned("a: &p [1, 2]\nb: *p\n", "x")
    assert problems == []
    assert doc is not None
    assert doc.data == {"a": [1, 2], "b": [1, 2]}
    assert doc.value_at(("b", 1)) == (2, 4)  # inside an alias: the alias's position


@given(
    st.recursive(
        st.none()
        | st.booleans()
        | st.integers(-(10**12), 10**12)
        | st.text(max_size=8)
        | st.floats(allow_nan=False, allow_infinity=False, width=32),
        lambda inner: (
            st.lists(inner, max_size=4)
            | st.dictionaries(st.text("abcxyz_", min_size=1, max_size=4), inner, max_size=4)
        ),
        max_leaves=20,
    )
)
def test_reader_agrees_with_pyyaml_on_plain_documents(value: object) -> None:
    text = yaml.safe_dump({"root": value})
    doc, problems = load_positioned(text, "x")
    expected = yaml.safe_load(text)
    if problems:  # only the finite-number rule may object (none here) or Y010
        assert {d.code for d in problems} <= {"Y010"}
        return
    assert doc is not None
    assert _same(doc.data, expected)


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a == b and type(a) is type(b)


_BIG_BOUNDARY = "[" + ", ".join(f"[{4 * i / 2000}, 0]" for i in range(2001)) + ", [4, 4], [0, 4]]"


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("rect: [0, 0, 4, 4]", "rect: [0, 0, 4e0, 4]"),
        ("start: [3, 3]", "start: [3e0, 3]"),
        ("{a: {rect: [1, 1, 2, 2]}}", "{a: [[1, 1], [2, 1], [2, 2e0]]}"),
        ("{rect: [0, 0, 4, 4]}", _BIG_BOUNDARY.replace("[4, 4]", "[4, 4e0]")),
    ],
)
def test_number_like_text_where_a_number_belongs_is_y010(old: str, new: str) -> None:
    assert old in VALID
    assert codes(VALID.replace(old, new)) == ["Y010"]


@pytest.mark.parametrize(
    "text",
    [
        VALID + "name: 1e3\n",
        VALID.replace("task: [visit a]", "task: [visit a]\nsensors: {s: {column: 2E5}}"),
    ],
)
def test_number_like_text_where_text_belongs_is_no_problem(text: str) -> None:
    # YAML 1.1 reads 1e3 as the text "1e3", which is what a name holds
    assert codes(text) == []


@pytest.mark.parametrize(("written", "suggested"), [("1e-6", "1.0e-6"), ("2E5", "2.0e+5")])
def test_yaml_11_exponent_without_dot_is_y010(written: str, suggested: str) -> None:
    problems = check_text(VALID.replace("max_speed: 1.0", f"max_speed: {written}"))
    assert [d.code for d in problems] == ["Y010"]
    assert suggested in (problems[0].hint or "")
    assert codes(VALID.replace("max_speed: 1.0", f"max_speed: {suggested}")) == []


@pytest.mark.parametrize("blank", ['"   "', '"\\t"', "|\n    \n"])
def test_blank_ltl_is_rejected_by_check(blank: str) -> None:
    text = VALID.replace("task: [visit a]", f"ltl: {blank}")
    assert "S020" in codes(text) or "S009" in codes(text)
    assert codes(text) != []


def test_second_document_and_undefined_alias_are_y001() -> None:
    assert codes(VALID + "---\nversion: 1\n") == ["Y001"]
    assert codes("a: *nowhere\n") == ["Y001"]


def test_a_huge_file_is_refused_while_reading(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    # (the memory bound is measured in a child process in test_big_missions)
    monkeypatch.setattr(load, "MAX_BYTES", 8 << 20)
    huge = tmp_path / "huge.yaml"
    with huge.open("wb") as stream:
        stream.truncate(1 << 30)  # sparse: a gigabyte long, no disk used
    with pytest.raises(UsageError) as caught:
        inspect_file(huge)
    assert caught.value.diagnostics[0].code == "U004"
    assert "8 MiB" in caught.value.diagnostics[0].message


def test_devices_and_fifos_are_refused_at_once(tmp_path: Path) -> None:
    fifo = tmp_path / "mission.yaml"
    os.mkfifo(fifo)  # no writer: opening it for reading the usual way would block forever
    for path in (Path("/dev/zero"), fifo, tmp_path):
        with pytest.raises(UsageError) as caught:
            inspect_file(path)
        assert caught.value.diagnostics[0].code == "U001"
        assert "not a regular file" in caught.value.diagnostics[0].message


def test_a_file_of_exactly_the_limit_is_read(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(load, "MAX_BYTES", 1 << 20)
    path = tmp_path / "m.yaml"
    path.write_text(VALID + "#" * ((1 << 20) - len(VALID) - 1) + "\n")
    assert path.stat().st_size == 1 << 20
    assert inspect_file(path)[1] == []
    path.write_text(VALID + "#" * ((1 << 20) - len(VALID)) + "\n")
    with pytest.raises(UsageError):
        inspect_file(path)


def test_large_boundary_geometry_is_checked_without_pairwise_loops() -> None:
    n = 200_000
    ring = [
        [50 + 40 * math.cos(2 * math.pi * k / n), 50 + 40 * math.sin(2 * math.pi * k / n)]
        for k in range(n)
    ]
    boundary, problems = check_shape(ring, ("b",), "boundary", "m", lambda p: (1, 1))
    assert problems == []
    assert boundary is not None
    crossed = list(ring)
    crossed[10], crossed[n // 2] = crossed[n // 2], crossed[10]
    _, problems = check_shape(crossed, ("b",), "boundary", "m", lambda p: (1, 1))
    assert [d.code for d in problems] == ["G004"]
    rects = {
        f"r{i}": check_shape(
            {"rect": [20 + i % 30, 20 + i // 30, 20.5 + i % 30, 20.5 + i // 30]},
            ("r", i),
            "r",
            "m",
            lambda p: (1, 1),
        )[0]
        for i in range(600)
    }
    holes = [
        check_shape(
            {"rect": [20.1 + k, 20.1, 20.2 + k, 20.2]}, ("h", k), "h", "m", lambda p: (1, 1)
        )[0]
        for k in range(30)
    ]
    regions = {k: v for k, v in rects.items() if v is not None}
    found = check_layout(
        boundary,
        [h for h in holes if h is not None],
        regions,
        (50, 50),
        ("s",),
        "m",
        lambda p: (1, 1),
    )
    outer = shapely_polygon(boundary)
    expected = ["G007" for r in regions.values() if not outer.covers(shapely_polygon(r))]
    expected += ["G005" for h in holes if h is not None and not outer.covers(shapely_polygon(h))]
    assert sorted(d.code for d in found) == sorted(expected)
    assert expected  # the layout has problems to find


def test_yaml_11_integer_forms_match_pyyaml() -> None:
    text = "a: [0x1f, 1_000, 0o17, -0, +5, 0b101, 007, 1.5, -.5, 1_0.5]\n"
    doc, problems = load_positioned(text, "x")
    assert problems == []
    assert doc is not None
    assert _same(doc.data, yaml.safe_load(text))
    # the forms YAML 1.1 reads in another base than their decimal digits are refused
    doc, problems = load_positioned("a: [012, 190:20:30]\n", "x")
    assert [(p.code, p.col) for p in problems] == [("Y011", 5), ("Y011", 10)]
