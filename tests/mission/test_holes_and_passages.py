"""Overlapping holes merged with a note; narrow passages warned about before meshing; progress."""

from __future__ import annotations

import io
import json
import threading
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from shapely import Polygon, union_all

from tlmpc.base.progress import heartbeat
from tlmpc.cli import main
from tlmpc.mission import load_mission_text
from tlmpc.mission.holes import merge_holes, narrow_passages, obstacle, workspace_notes

ROOT = Path(__file__).resolve().parents[2]


def _rect(x0: float, y0: float, x1: float, y1: float) -> tuple[tuple[float, float], ...]:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


rects = st.builds(
    lambda x, y, w, h: _rect(x, y, x + w, y + h),
    st.integers(1, 15),
    st.integers(1, 15),
    st.integers(1, 4),
    st.integers(1, 4),
)


@given(st.lists(rects, min_size=1, max_size=7))
def test_merging_keeps_the_obstacle_and_leaves_no_overlap(
    holes: list[tuple[tuple[float, float], ...]],
) -> None:
    merged = merge_holes(holes)
    shapes = [Polygon(h) for h in merged.holes]
    original = union_all([Polygon(h) for h in holes])
    covered = union_all(shapes)
    # the same obstacle (plus the free pockets it enclosed, when it enclosed some)
    assert covered.symmetric_difference(original).area == 0 or any(merged.enclosed)
    assert covered.covers(original)
    for i, first in enumerate(shapes):
        assert first.is_valid
        for second in shapes[i + 1 :]:
            assert first.intersection(second).area == 0
    # every original hole is accounted for exactly once
    assert sorted(i for group in merged.sources for i in group) == list(range(len(holes)))
    for group, shape in zip(merged.sources, shapes, strict=True):
        if len(group) == 1:
            assert merged.holes[merged.sources.index(group)] == holes[group[0]]
        for i in group:
            assert shape.covers(Polygon(holes[i]))


MISSION = """\
version: 1
workspace:
  boundary: {{rect: [0, 0, 10, 10]}}
  holes:
{holes}
regions:
  goal: {{rect: [8, 8, 9, 9]}}
robot: {{start: [0.5, 0.5]}}
task:
  - visit goal
"""


def _mission(tmp_path: Path, holes: list[str]) -> Path:
    path = tmp_path / "mission.yaml"
    path.write_text(MISSION.format(holes="\n".join(f"    - {h}" for h in holes)))
    return path


def test_overlapping_holes_compile_with_a_note(tmp_path: Path) -> None:
    path = _mission(
        tmp_path, ["{rect: [3, 3, 5, 5]}", "{rect: [1, 8, 2, 9]}", "{rect: [4, 4, 6, 6]}"]
    )
    err = io.StringIO()
    assert main(["check", str(path)], out=io.StringIO(), err=err) == 0
    assert f"{path}:5: note[G020]: holes 1 and 3 overlap: merged into one obstacle" in (
        err.getvalue()
    )
    out = tmp_path / "out"
    err = io.StringIO()
    assert main(["compile", str(path), "-o", str(out), "-q"], out=io.StringIO(), err=err) == 0
    assert "note[G020]" in err.getvalue()
    holes = json.loads((out / "mission.json").read_text())["workspace"]["holes"]
    assert len(holes) == 2
    assert Polygon(holes[0]).area == 4 + 4 - 1
    assert json.loads((out / "verdict.json").read_text())["satisfied"] is True


@given(st.lists(rects, min_size=1, max_size=7))
def test_the_checked_obstacle_is_the_compiled_one(
    holes: list[tuple[tuple[float, float], ...]],
) -> None:
    """``tlmpc check`` refuses a region or start by the obstacle the compile triangulates."""
    checked = obstacle([Polygon(h) for h in holes])
    compiled = union_all([Polygon(h) for h in merge_holes(holes).holes])
    assert checked.symmetric_difference(compiled).area == 0


RING = [
    "{rect: [2, 2, 8, 3]}",
    "{rect: [7, 2, 8, 8]}",
    "{rect: [2, 7, 8, 8]}",
    "{rect: [2, 2, 3, 8]}",
]


@pytest.mark.parametrize(
    ("goal", "start", "code", "line"),
    [("[4, 4, 6, 6]", "[0.5, 0.5]", "G008", 10), ("[8, 8, 9, 9]", "[5, 5]", "G010", 11)],
)
def test_a_region_or_start_in_a_pocket_of_overlapping_holes_is_refused_by_check(
    tmp_path: Path, goal: str, start: str, code: str, line: int
) -> None:
    path = _mission(tmp_path, RING)
    text = path.read_text()
    text = text.replace("[8, 8, 9, 9]", goal).replace("[0.5, 0.5]", start)
    path.write_text(text)
    err = io.StringIO()
    assert main(["check", str(path)], out=io.StringIO(), err=err) == 1
    assert f"{path}:{line}:" in err.getvalue()
    assert f"error[{code}]" in err.getvalue()


def test_a_region_in_a_pocket_of_a_second_pieces_overlapping_holes_is_g008(
    tmp_path: Path,
) -> None:
    """The same rule in every piece of a workspace with components."""
    holes = ", ".join(
        f"{{rect: [{x0 + 20}, {y0}, {x1 + 20}, {y1}]}}"
        for x0, y0, x1, y1 in [(2, 2, 8, 3), (7, 2, 8, 8), (2, 7, 8, 8), (2, 2, 3, 8)]
    )
    path = tmp_path / "pieces.yaml"
    path.write_text(
        "version: 1\n"
        "workspace:\n"
        "  boundary: {rect: [0, 0, 10, 10]}\n"
        f"  components: [{{boundary: {{rect: [20, 0, 30, 10]}}, holes: [{holes}]}}]\n"
        "regions:\n"
        "  goal: {rect: [24, 4, 26, 6]}\n"
        "robot: {start: [0.5, 0.5]}\n"
        "task:\n"
        "  - visit goal\n"
    )
    err = io.StringIO()
    assert main(["check", str(path)], out=io.StringIO(), err=err) == 1
    assert f"{path}:6:" in err.getvalue()
    assert "error[G008]" in err.getvalue()


def test_holes_that_only_touch_are_kept() -> None:
    merged = merge_holes([_rect(1, 1, 2, 2), _rect(2, 1, 3, 2), _rect(3, 2, 4, 3)])
    assert merged.sources == ((0,), (1,), (2,))


@given(st.floats(1e-7, 0.05), st.floats(0.1, 2.0))
def test_a_gap_between_two_holes_is_reported_iff_narrow(gap: float, height: float) -> None:
    left = _rect(2, 4, 5, 4 + height)
    right = _rect(5 + gap, 4, 8, 4 + height)
    found = narrow_passages(_rect(0, 0, 10, 10), [left, right])
    limit = 1e-3 * 10
    if gap < limit * (1 - 1e-9):
        assert len(found) == 1
        width, a, b, ring = found[0]
        assert abs(width - gap) <= 1e-9
        assert ring == 2
        assert abs(a[0] - 5) < 1e-9 or abs(b[0] - 5) < 1e-9
        assert 4 - 1e-9 <= (a[1] + b[1]) / 2 <= 4 + height + 1e-9
    elif gap > limit * (1 + 1e-9):
        assert found == []


def test_a_thin_obstacle_or_a_sharp_corner_is_no_passage() -> None:
    spike = ((3.0, 3.0), (6.0, 3.0), (6.0, 3.00001), (3.0, 3.00001))  # a hair of a hole
    notch = ((2.0, 6.0), (4.0, 6.0), (2.0, 6.00001))  # a needle-sharp corner
    assert narrow_passages(_rect(0, 0, 10, 10), [spike, notch]) == []


def test_narrow_door_in_the_boundary_is_located(tmp_path: Path) -> None:
    # two rooms joined by a 10 µm door in the boundary outline itself
    text = (
        "version: 1\nworkspace:\n  boundary: [[0, 0], [4, 0], [4, 1.99999], [6, 1.99999], "
        "[6, 0], [10, 0], [10, 4], [6, 4], [6, 2], [4, 2], [4, 4], [0, 4]]\n"
        "regions:\n  goal: {rect: [8, 1, 9, 2]}\nrobot: {start: [1, 1]}\ntask:\n  - visit goal\n"
    )
    mission = load_mission_text(text, "door.yaml")
    _, notes = workspace_notes(mission, text)
    assert [n.code for n in notes] == ["G021"]
    assert notes[0].line == 3
    assert notes[0].severity == "warning"
    assert "1e-05 wide at (" in notes[0].message


def test_shipped_missions_have_no_narrow_passage() -> None:
    for spec in sorted((ROOT / "specs").glob("*.yaml")):
        mission = load_mission_text(spec.read_text(), str(spec))
        assert workspace_notes(mission)[1] == [], spec.name


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_heartbeat_on_a_terminal() -> None:
    stream = _Terminal()
    seen = threading.Event()

    class Watch(_Terminal):
        def write(self, text: str) -> int:
            if "meshing" in text:
                seen.set()
            return stream.write(text)

    with heartbeat("meshing", Watch(), first=0.0, every=0.01):
        assert seen.wait(60)
    text = stream.getvalue()
    assert text.startswith("\r… meshing:")
    assert text.endswith("\r\033[K")


def test_no_heartbeat_for_a_short_stage() -> None:
    stream = io.StringIO()
    with heartbeat("meshing", stream, first=60.0):
        pass
    assert stream.getvalue() == ""


def test_a_heartbeat_into_a_pipe_writes_whole_lines() -> None:
    # not a terminal (a CI log, a file): lines, not a status line rewritten in place
    stream = io.StringIO()
    seen = threading.Event()

    class Watch(io.StringIO):
        def write(self, text: str) -> int:
            if "running for" in text:
                seen.set()
            return stream.write(text)

    with heartbeat("meshing", Watch(), first=0.0):
        assert seen.wait(60)
    lines = stream.getvalue().splitlines(keepends=True)
    assert lines[0].startswith("… meshing: running for ")
    assert lines[-1].startswith("… meshing: done in ")
    assert all(line.endswith("\n") and "\r" not in line for line in lines)


def test_a_narrow_gap_between_holes_is_reported_at_the_hole(tmp_path: Path) -> None:
    path = _mission(
        tmp_path, ["{rect: [2, 2, 5, 6]}", "{rect: [1, 8, 2, 9]}", "{rect: [5.00001, 2, 8, 6]}"]
    )
    err = io.StringIO()
    assert main(["check", str(path)], out=io.StringIO(), err=err) == 0
    assert f"{path}:7: warning[G021]: a passage only 1e-05 wide at (5, " in err.getvalue()


def test_compile_reports_long_stages_into_a_pipe_unless_quiet(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import tlmpc.base.progress as progress

    monkeypatch.setattr(progress, "FIRST", 0.0)  # every stage counts as long
    mission = Path(__file__).resolve().parents[2] / "specs" / "example1.yaml"
    out = tmp_path / "out"
    assert main(["compile", str(mission), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "… abstraction: running for" in err or "… abstraction: done in" in err
    assert "\r" not in err  # not a terminal: whole lines
    assert main(["compile", str(mission), "-o", str(out), "-q"]) == 0
    assert "…" not in capsys.readouterr().err
