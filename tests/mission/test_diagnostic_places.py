"""Where the body's warnings (R002-R004) and a task's translation budget (P041) are placed.

A workspace taken from a map has no boundary, holes or mask regions written in the mission:
their diagnostics belong where the map or the mask is named, with a column.  A task whose
negation normal form is beyond the budget is refused at the task entry that causes it.  The
expected places are found in the mission's text by the test itself (the line holding the
entry, the column of its text), not read back from tlmpc's positions.
"""

from __future__ import annotations

import io
from pathlib import Path

from tlmpc.cli import main
from tlmpc.mission.cspace import body_diagnostics
from tlmpc.mission.load import check_file, load_mission

CELLS = 40
MAP_META = (
    "image: {image}\nresolution: 0.1\norigin: [-1.0, -1.0, 0.0]\nnegate: 0\n"
    "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
)


def _write_map(folder: Path, stem: str, occupied: set[tuple[int, int]]) -> None:
    """A map_server map of CELLS x CELLS cells (0.1 m) whose ``occupied`` (column, row)
    cells are black and the others white, as a binary PGM and its YAML."""
    pixels = bytearray(
        0 if (column, row) in occupied else 254 for row in range(CELLS) for column in range(CELLS)
    )
    header = f"P5\n{CELLS} {CELLS}\n255\n".encode()
    (folder / f"{stem}.pgm").write_bytes(header + bytes(pixels))
    (folder / f"{stem}.yaml").write_text(MAP_META.format(image=f"{stem}.pgm"))


def _text_place(text: str, line_start: str, value: str) -> tuple[int, int]:
    """1-based line and column of ``value`` on the line that starts with ``line_start``."""
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith(line_start):
            return number, line.index(value) + 1
    raise AssertionError(f"no line starts with {line_start!r}")


def _map_mission(folder: Path) -> Path:
    """A room split by a wall with a gap of two cells (narrower than the body), a keepout
    mask marking a strip two cells wide along that wall (within the body's radius of it)
    and a big square in the open, and the mission's own regions, the second against the
    room's left wall."""
    walls = {(i, 0) for i in range(CELLS)} | {(i, CELLS - 1) for i in range(CELLS)}
    walls |= {(0, i) for i in range(CELLS)} | {(CELLS - 1, i) for i in range(CELLS)}
    walls |= {(20, row) for row in range(CELLS) if row not in (18, 19)}
    _write_map(folder, "room", walls)
    strip = {(column, row) for column in (18, 19) for row in range(4, 12)}
    square = {(column, row) for column in range(28, 33) for row in range(28, 33)}
    _write_map(folder, "keep", strip | square)
    mission = folder / "mission.yaml"
    mission.write_text(
        "version: 1\n"
        "name: places\n"
        "workspace: {map: room.yaml, keepout: keep.yaml}\n"
        "regions:\n"
        "  home: {rect: [0, 0, 0.5, 0.5]}\n"
        "  nook: {rect: [-0.9, 0.5, -0.8, 0.6]}\n"
        "robot: {start: [0, 0], radius: 0.2, max_speed: 0.5}\n"
        "task:\n"
        "  - visit home\n"
        "  - avoid keepout\n"
    )
    return mission


def _places(path: Path) -> dict[tuple[str, str], tuple[int | None, int | None]]:
    """(code, region name or "") -> (line, col) of the body's warnings on the mission."""
    found = {}
    for d in body_diagnostics(load_mission(path)):
        name = d.message.split("'")[1] if d.code in ("R003", "R004") else ""
        assert d.file == str(path)
        found[(d.code, name)] = (d.line, d.col)
    return found


def test_map_workspace_warnings_are_at_the_map_with_a_column(tmp_path: Path) -> None:
    mission = _map_mission(tmp_path)
    text = mission.read_text()
    places = _places(mission)
    assert places[("R002", "")] == _text_place(text, "workspace:", "room.yaml")


def test_mask_regions_are_at_their_mask_and_own_regions_at_their_entry(
    tmp_path: Path,
) -> None:
    mission = _map_mission(tmp_path)
    text = mission.read_text()
    places = _places(mission)
    keepout = _text_place(text, "workspace:", "keep.yaml")
    imported = {name: at for (code, name), at in places.items() if name.startswith("keepout_")}
    # the strip along the wall cannot be entered (R003), the square lies beyond the gap (R004)
    assert {code for code, name in places if name.startswith("keepout_")} == {"R003", "R004"}
    assert set(imported.values()) == {keepout}
    assert places[("R003", "nook")] == _text_place(text, "  nook:", "{rect")


def test_drawn_workspace_warnings_have_a_column(tmp_path: Path) -> None:
    mission = tmp_path / "drawn.yaml"
    mission.write_text(
        "version: 1\n"
        "name: drawn\n"
        "workspace:\n"
        # two rooms joined by a door 0.2 wide, narrower than the body
        "  boundary: [[0, 0], [2, 0], [2, 1.9], [2.2, 1.9], [2.2, 0], [4, 0], [4, 4],\n"
        "             [2.2, 4], [2.2, 2.1], [2, 2.1], [2, 4], [0, 4]]\n"
        "regions:\n"
        "  corner: {rect: [0, 3.9, 0.1, 4]}\n"
        "  far: {rect: [3, 3, 3.5, 3.5]}\n"
        "robot: {start: [1, 1], radius: 0.2}\n"
        "task:\n"
        "  - visit far\n"
    )
    text = mission.read_text()
    places = _places(mission)
    assert places[("R003", "corner")] == _text_place(text, "  corner:", "{rect")
    assert places[("R002", "")] == _text_place(text, "  boundary:", "[[")


def _equivalence_chain(count: int) -> str:
    """``F (p{count-1} <-> (... (p1 <-> p0)))``: each ``<->`` doubles the normal form."""
    formula = "p0"
    for index in range(1, count):
        formula = f"p{index} <-> {formula}" if index == count - 1 else f"(p{index} <-> {formula})"
    return f"F ({formula})"


def _budget_mission(folder: Path) -> Path:
    regions = "".join(f"  p{i}: {{rect: [{i}, 0, {i}.5, 0.5]}}\n" for i in range(26))
    mission = folder / "chain.yaml"
    mission.write_text(
        "version: 1\n"
        "name: chain\n"
        "workspace: {boundary: [[0, 0], [27, 0], [27, 2], [0, 2]]}\n"
        f"regions:\n{regions}"
        "robot: {start: [0.2, 1]}\n"
        "task:\n"
        "  - visit p3\n"
        f'ltl: "{_equivalence_chain(26)}"\n'
    )
    return mission


def test_normal_form_budget_is_refused_at_the_ltl_entry(tmp_path: Path) -> None:
    mission = _budget_mission(tmp_path)
    text = mission.read_text()
    expected = _text_place(text, "ltl:", "F (")
    [refusal] = [d for d in check_file(mission) if d.code == "P041"]
    assert (refusal.file, refusal.line, refusal.col) == (str(mission), *expected)
    assert refusal.path == "$.ltl"
    out, err = io.StringIO(), io.StringIO()
    assert main(["check", str(mission)], out=out, err=err) == 1
    assert f"{mission}:{expected[0]}:{expected[1]}: error[P041]" in out.getvalue() + err.getvalue()


def test_a_chain_within_the_budget_loads(tmp_path: Path) -> None:
    mission = _budget_mission(tmp_path)
    mission.write_text(mission.read_text().replace(_equivalence_chain(26), _equivalence_chain(8)))
    assert check_file(mission) == []
