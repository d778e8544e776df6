"""Big missions: long number lists read in bulk, located exactly, bounded reading.

The oracle for the bulk reader is the ordinary event-by-event reader (the shortcut switched
off) and PyYAML itself: same data, same diagnostics, same positions, on documents that put
long lists everywhere a YAML file can (flow and block context, anchors, comments, quoted
strings, keys, CRLF line ends, spellings YAML reads differently from JSON).
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
import shapely
import yaml
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tlmpc.base.errors import UsageError
from tlmpc.mission import bulk, yamlpos
from tlmpc.mission.holes import narrow_passages, passage_search
from tlmpc.mission.load import check_text, inspect_file
from tlmpc.mission.yamlpos import PositionedDocument, load_positioned

ROOT = Path(__file__).resolve().parents[2]


def _ordinary(text: str, file: str = "m.yaml") -> tuple[PositionedDocument | None, list[str]]:
    converter = yamlpos._Converter(file)
    doc, problems = yamlpos._result(converter, yamlpos._convert(converter, text), file)
    return doc, [d.format() for d in problems]


def _fast(text: str, file: str = "m.yaml") -> tuple[PositionedDocument | None, list[str]]:
    doc, problems = load_positioned(text, file)
    return doc, [d.format() for d in problems]


def _ring(n: int, radius: float = 40.0) -> list[list[float]]:
    return [
        [
            round(50 + radius * math.cos(2 * math.pi * k / n), 6),
            round(50 + radius * math.sin(2 * math.pi * k / n), 6),
        ]
        for k in range(n)
    ]


def _mission(boundary: str) -> str:
    return (
        "version: 1\n"
        f"workspace:\n  boundary: {boundary}\n"
        "regions: {a: {rect: [45, 45, 55, 55]}}\n"
        "robot: {start: [50, 50]}\n"
        "task: [visit a]\n"
    )


def _points_text(points: list[list[float]], per_line: int, indent: str = "    ") -> str:
    rows = [
        ", ".join(f"[{x!r}, {y!r}]" for x, y in points[i : i + per_line])
        for i in range(0, len(points), per_line)
    ]
    return "[" + (",\n" + indent).join(rows) + "]"


# --- the bulk reader agrees with the ordinary one -------------------------------------------

_number = st.one_of(
    st.integers(-(10**6), 10**6).map(str),
    st.floats(-1e6, 1e6, allow_nan=False).map(repr),
    st.sampled_from(["1e5", "1.5e5", "1.5e+5", "-2.0E-3", "1.0e+999", "12345678901234567", "-0"]),
    st.sampled_from(['"far"', "true", "null", '"a,b"', '"x\\ty"', '"\u00e9t"', '"#"', "+1.5"]),
)


@st.composite
def _list_text(draw: st.DrawFn) -> str:
    """A list of about 500 points, some spellings YAML reads differently from JSON."""
    count = draw(st.integers(400, 600))
    odd = draw(st.lists(st.tuples(st.integers(0, count - 1), _number), max_size=3))
    points = [[f"{k}.5", f"{-k}.25"] for k in range(count)]
    for index, number in odd:
        points[index][1] = number
    per_line = draw(st.sampled_from([1, 7, count]))
    rows = [
        ", ".join(f"[{x}, {y}]" for x, y in points[i : i + per_line])
        for i in range(0, count, per_line)
    ]
    return "[" + ",\n   ".join(rows) + draw(st.sampled_from(["]", ",]", " ]"]))


_PLACES = [
    "a: {list}\nb: 1\n",
    "a: {{x: {list}, y: 2}}\n",
    "a:\n  - {list}\n  - 3\n",
    "a: &anchor {list}\nb: *anchor\n",
    "a: !!seq {list}\n",
    "# {list}\na: 1\n",
    'a: "{list}"\n',
    "a: x{list}\n",
    "{list}: 1\n",
    "a: [{list}, [1, 2]]\n",
    "a: {list} tail\n",
    "a: {list}\nb: [1, 2\n",
    "a: {list}\n  b: 1\n",
    '{{"a": {list}, "b": [1]}}\n',
    "a: |\n  {list}\n",
]


#: A long list whose numbers are spelled as JSON allows and YAML 1.1 does not (``1e5`` is a
#: string to PyYAML): the bulk reader must leave it to the ordinary one.
_JSON_ONLY_NUMBERS = "[" + ", ".join(f"[{k}.5, 1e{k % 3 + 1}]" for k in range(500)) + "]"


@pytest.mark.slow
@settings(deadline=None)
@given(
    place=st.sampled_from(_PLACES),
    body=_list_text(),
    crlf=st.booleans(),
    probes=st.lists(st.tuples(st.integers(0, 700), st.integers(0, 2)), max_size=5),
)
@example(place=_PLACES[0], body=_JSON_ONLY_NUMBERS, crlf=False, probes=[(3, 1)])
def test_bulk_reader_agrees_with_the_ordinary_reader(
    place: str, body: str, crlf: bool, probes: list[tuple[int, int]]
) -> None:
    text = place.format(list=body)
    if crlf:
        text = text.replace("\n", "\r\n")
    fast_doc, fast_problems = _fast(text)
    slow_doc, slow_problems = _ordinary(text)
    assert fast_problems == slow_problems
    assert (fast_doc is None) == (slow_doc is None)
    if fast_doc is None or slow_doc is None:
        return
    assert fast_doc.data == slow_doc.data
    assert _types(fast_doc.data) == _types(slow_doc.data)
    for index, coordinate in probes:
        for root in [("a",), ("a", "x"), ("a", 0), ("b",)]:
            path = (*root, index, coordinate)
            assert fast_doc.value_at(path) == slow_doc.value_at(path), path
            assert fast_doc.value_at(path[:-1]) == slow_doc.value_at(path[:-1]), path


_DEEP = "b: " + "[" * 70 + "]" * 70 + "\n"  # stops reading (Y003) after the list


@pytest.mark.parametrize(
    "place",
    [
        *_PLACES,
        "? {list}\n: 1\n",
        "? {list}\n: 1\n" + _DEEP,
        "a: !!seq {list}\n" + _DEEP,
        "a: x{list}\n" + _DEEP,
        "# {list}\n" + _DEEP,
        "a:\n" + "  " * 40 + "b: {list}\n",
    ],
)
@pytest.mark.parametrize("word", ["1.5", '"far"'])
def test_every_place_agrees(place: str, word: str) -> None:
    body = "[" + ", ".join(f"[{k}.5, {word if k == 300 else k}]" for k in range(500)) + "]"
    text = place.format(list=body)
    fast_doc, fast_problems = _fast(text)
    slow_doc, slow_problems = _ordinary(text)
    assert fast_problems == slow_problems
    assert (fast_doc is None) == (slow_doc is None)
    if fast_doc is not None and slow_doc is not None:
        assert fast_doc.data == slow_doc.data
        for path in [("a", 300, 1), ("a", 0), ("a", "x", 300, 1), ("b", 7)]:
            assert fast_doc.value_at(path) == slow_doc.value_at(path), path


def _types(value: object) -> object:
    if isinstance(value, dict):
        return {k: _types(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_types(v) for v in value]
    return type(value).__name__


def test_bulk_reader_is_used_on_a_long_list() -> None:
    text = _mission(_points_text(_ring(2000), 10))
    doc, problems = load_positioned(text, "m.yaml")
    assert problems == []
    assert doc is not None
    assert ("workspace", "boundary") in doc.bulk  # the shortcut ran
    assert doc.data == yaml.safe_load(text)


def test_a_mistake_in_a_quoted_string_is_not_read_as_a_list() -> None:
    body = _points_text(_ring(1000), 1000)
    text = f'name: "{body}"\n'
    doc, problems = load_positioned(text, "m.yaml")
    assert problems == []
    assert doc is not None
    assert doc.data == {"name": body}


# --- 10^5 vertices: valid, and mistakes deep inside located exactly ---------------------------


def _big_ring_text(n: int = 100_000) -> tuple[str, list[list[float]]]:
    points = _ring(n)
    return _mission(_points_text(points, 4)), points


def test_a_hundred_thousand_vertex_boundary_is_valid() -> None:
    text, _ = _big_ring_text()
    assert check_text(text, "m.yaml") == []


def _place(text: str, needle: str) -> tuple[int, int]:
    offset = text.index(needle)
    return text.count("\n", 0, offset) + 1, offset - text.rfind("\n", 0, offset)


def test_a_bad_coordinate_deep_in_a_big_boundary_is_located() -> None:
    text, points = _big_ring_text()
    index = 91_237
    x, y = points[index]
    written = f"[{x!r}, {y!r}]"
    assert text.count(written) == 1
    broken = text.replace(written, f'[{x!r}, "far"]')
    doc, _ = load_positioned(broken, "m.yaml")
    assert doc is not None
    assert ("workspace", "boundary") in doc.bulk  # read in bulk despite the mistake
    problems = check_text(broken, "m.yaml")
    assert [d.code for d in problems] == ["S005"]
    line, col = _place(broken, '"far"')
    assert (problems[0].line, problems[0].col) == (line, col)
    assert problems[0].path == f"$.workspace.boundary[{index}][1]"


def test_a_json_mission_with_a_big_boundary_is_checked() -> None:
    points = _ring(100_000)
    document = {
        "version": 1,
        "workspace": {"boundary": points},
        "regions": {"a": {"rect": [45, 45, 55, 55]}},
        "robot": {"start": [50, 50]},
        "task": ["visit a"],
    }
    assert check_text(json.dumps(document), "m.json") == []
    points[77_777] = [points[77_777][0], 2e9]  # out of range
    text = json.dumps(document)
    problems = check_text(text, "m.json")
    assert [d.code for d in problems] == ["S010"]
    assert (problems[0].line, problems[0].col) == _place(text, "2000000000.0")


def test_a_crossing_deep_in_a_big_boundary_is_located_at_its_edge() -> None:
    _, points = _big_ring_text()
    a, b = 60_000, 60_500
    swapped = [list(p) for p in points]
    swapped[a], swapped[b] = swapped[b], swapped[a]
    broken = _mission(_points_text(swapped, 4))
    problems = check_text(broken, "m.yaml")
    assert [d.code for d in problems] == ["G004"]
    assert problems[0].path is not None
    vertex = int(problems[0].path.rsplit("[", 1)[1].rstrip("]"))
    x, y = swapped[vertex]
    assert (problems[0].line, problems[0].col) == _place(broken, f"[{x!r}, {y!r}]")
    # the edge leaving that vertex really crosses another, non-adjacent edge (shapely)
    n = len(swapped)
    edge = shapely.LineString([swapped[vertex], swapped[(vertex + 1) % n]])
    others = [
        shapely.LineString([swapped[k], swapped[(k + 1) % n]])
        for k in range(n)
        if k not in {(vertex - 1) % n, vertex, (vertex + 1) % n}
    ]
    assert any(edge.intersects(o) for o in others)


# --- narrow passages of finely sampled outlines ----------------------------------------------


def test_a_finely_sampled_circle_has_no_narrow_passage() -> None:
    ring = tuple((x, y) for x, y in _ring(20_000))
    assert narrow_passages(ring, []) == []


def test_a_finely_rounded_corner_is_no_passage() -> None:
    # a 100 x 100 square whose corner is rounded with radius 0.05 in 60 steps: neighbouring
    # arc edges are closer than the limit (0.1), but the ring between them is no deeper
    arc = [
        (99.95 + 0.05 * math.cos(t), 99.95 + 0.05 * math.sin(t))
        for t in (math.pi / 2 * k / 59 for k in range(60))
    ]
    outline = ((0.0, 0.0), (100.0, 0.0), *arc, (0.0, 100.0))
    assert shapely.Polygon(outline).is_valid
    assert narrow_passages(outline, []) == []


def test_a_narrow_channel_between_finely_sampled_rooms_is_found() -> None:
    # two round rooms of 8,000 vertices each joined by a channel 0.01 wide (the limit is 0.09)
    rooms = shapely.union_all(
        [
            shapely.Point(30, 50).buffer(20, quad_segs=2000),
            shapely.box(49.9, 49.995, 60.1, 50.005),
            shapely.Point(80, 50).buffer(20, quad_segs=2000),
        ]
    )
    assert isinstance(rooms, shapely.Polygon)
    outline = tuple((x, y) for x, y in rooms.exterior.coords[:-1])
    assert len(outline) > 15_000
    found = narrow_passages(outline, [])
    assert len(found) == 1
    width, a, b, _ = found[0]
    assert width == pytest.approx(0.01, rel=1e-6)
    assert 49.9 <= a[0] <= 60.1
    assert 49.9 <= b[0] <= 60.1


def test_the_passage_search_stops_at_its_budget() -> None:
    ring = tuple((float(x), float(y)) for x, y in _ring(20_000))
    holes = [((30.0, 30.0), (31.0, 30.0), (31.0, 30.5))]
    assert not passage_search(ring, holes, max_pairs=10)[1]
    assert passage_search(ring, holes)[1]


# --- the read limit is checked while reading ---------------------------------------------------


def test_a_device_is_refused_at_once() -> None:
    with pytest.raises(UsageError) as caught:
        inspect_file("/dev/zero")
    assert caught.value.diagnostics[0].code == "U001"
    assert "device" in caught.value.diagnostics[0].message


def test_a_huge_file_is_cut_at_the_limit(tmp_path: Path) -> None:
    # a sparse file: 64 MiB long, no disk used; read up to the limit and no further
    huge = tmp_path / "huge.yaml"
    with huge.open("wb") as stream:
        stream.truncate(64 << 20)
    # VmHWM is the peak of this process image alone; ru_maxrss would also count the pytest
    # worker the child was forked from
    script = (
        "import re, sys; from tlmpc.mission import load\n"
        "load.MAX_BYTES = 32 << 20\n"
        "from tlmpc.base.errors import UsageError\n"
        f"try:\n    load.inspect_file({str(huge)!r})\n"
        "except UsageError as exc:\n    print(exc.diagnostics[0].code)\n"
        "status = open('/proc/self/status').read()\n"
        "print(re.search(r'VmHWM:\\s*(\\d+) kB', status).group(1))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        capture_output=True,
        text=True,
        check=True,
    )
    code, peak_kb = done.stdout.split()
    assert code == "U004"
    # the interpreter and its imports, plus the limit once (and a piece): not the stream
    assert int(peak_kb) * 1024 < 200 * 2**20 + 2 * (32 << 20)


def test_the_bulk_budget_sends_huge_lists_the_ordinary_way(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(bulk, "MAX_VALUES", 1000)
    text = _mission(_points_text(_ring(2000), 10))
    doc, problems = load_positioned(text, "m.yaml")
    assert problems == []
    assert doc is not None
    assert doc.bulk == {}
    assert doc.data == yaml.safe_load(text)


def test_a_short_list_where_a_run_starts_is_not_cut_out() -> None:
    # The run of number characters starts after the word in the first point; the list the
    # JSON decoder reads there is that one short point.  Cut out, its placeholder (longer
    # than the point) moved every later column of the line (found by the property above).
    points = [[f"{k}.5", f"{-k}.25"] for k in range(400)]
    points[0][1] = '"far"'
    rows = [
        ", ".join(f"[{x}, {y}]" for x, y in points[i : i + 7]) for i in range(0, len(points), 7)
    ]
    text = "a: [" + ",\n   ".join(rows) + "]\nb: 1\n"
    fast_doc, fast_problems = _fast(text)
    slow_doc, slow_problems = _ordinary(text)
    assert fast_problems == slow_problems
    assert fast_doc is not None
    assert slow_doc is not None
    for index in range(12):
        path = ("a", index, 0)
        assert fast_doc.value_at(path) == slow_doc.value_at(path), path
