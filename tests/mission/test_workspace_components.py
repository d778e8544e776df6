"""Workspaces of several disjoint pieces of free space (``workspace.components``).

Each piece is checked, triangulated, labelled, planned in, verified, plotted and exported;
the oracles are shapely (areas, containment) and graph facts computed from the mesh alone.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon, shape

from tlmpc.abstraction import build_abstraction
from tlmpc.api import compile as compile_mission
from tlmpc.base.errors import NoPlanError
from tlmpc.cli import main
from tlmpc.io.schema_check import validation_errors
from tlmpc.ltl.ast import TRUE
from tlmpc.mission.io import mission_from_json
from tlmpc.mission.load import check_text, load_mission_text
from tlmpc.mission.model import Component, Mission, Options, Region, Robot, Workspace
from tlmpc.verify import from_document, verify_trace

Ring = tuple[tuple[float, float], ...]


def rect(x0: float, y0: float, x1: float, y1: float) -> Ring:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


#: A room with a pillar that encloses a pocket of free space, and a second room beside it.
ROOMS: dict[str, Any] = {
    "version": 1,
    "workspace": {
        "boundary": {"rect": [0, 0, 10, 10]},
        "holes": [{"rect": [4, 4, 8, 8]}],
        "components": [
            {"boundary": {"rect": [5, 5, 7, 7]}},
            {"boundary": {"rect": [12, 0, 16, 4]}, "holes": [{"rect": [13, 1, 14, 2]}]},
        ],
    },
    "regions": {
        "a": {"rect": [1, 1, 2, 2]},
        "b": {"rect": [8.5, 8.5, 9.5, 9.5]},
        "pocket": {"rect": [5.5, 5.5, 6.5, 6.5]},
        "far": {"rect": [15, 3, 16, 4]},
    },
    "robot": {"start": [0.5, 0.5]},
    "task": ["visit a then b"],
}


def rooms(**changes: Any) -> dict[str, Any]:
    document: dict[str, Any] = json.loads(json.dumps(ROOMS))
    for key, value in changes.items():
        target = document
        *path, last = key.split(".")
        for part in path:
            target = target[part]
        target[last] = value
    return document


def text(document: dict[str, Any]) -> str:
    return yaml.safe_dump(document, sort_keys=False)


def free_area_oracle(document: dict[str, Any]) -> Any:
    """The union of every piece's boundary minus its own holes, from the document alone."""

    def poly(value: Any) -> Polygon:
        if isinstance(value, dict):
            return shapely.box(*value["rect"])
        return Polygon(value)

    workspace = document["workspace"]
    pieces = [{"boundary": workspace["boundary"], "holes": workspace.get("holes", [])}]
    pieces += workspace.get("components", [])
    free = [
        poly(p["boundary"]).difference(shapely.union_all([poly(h) for h in p.get("holes", [])]))
        for p in pieces
    ]
    return shapely.union_all(free)


# --- loading and checking ----------------------------------------------------------------


def test_components_load_and_round_trip_through_mission_json() -> None:
    mission = load_mission_text(text(ROOMS), "rooms.yaml")
    assert len(mission.workspace.components) == 2
    assert mission.workspace.components[1].holes == (rect(13, 1, 14, 2),)
    document = mission.to_json()
    assert validation_errors(document, "mission-artifact") == []
    again = mission_from_json(document)
    assert again.workspace == mission.workspace
    assert [p.boundary for p in again.workspace.pieces] == [
        rect(0, 0, 10, 10),
        rect(5, 5, 7, 7),
        rect(12, 0, 16, 4),
    ]


def test_a_mission_without_components_writes_no_components_key() -> None:
    plain = rooms()
    del plain["workspace"]["components"]
    plain["regions"] = {"a": {"rect": [1, 1, 2, 2]}, "b": {"rect": [8.5, 8.5, 9.5, 9.5]}}
    document = load_mission_text(text(plain), "plain.yaml").to_json()
    assert "components" not in document["workspace"]


@pytest.mark.parametrize(
    ("change", "code", "line_of"),
    [
        # overlapping the main piece's free space
        ({"workspace.components": [{"boundary": {"rect": [1, 1, 3, 3]}}]}, "M100", "components"),
        # overlapping another component
        (
            {
                "workspace.components": [
                    {"boundary": {"rect": [12, 0, 16, 4]}},
                    {"boundary": {"rect": [15, 3, 18, 6]}},
                ]
            },
            "M100",
            "components",
        ),
        # a component's hole outside its own boundary (inside the main piece's instead)
        (
            {
                "workspace.components": [
                    {"boundary": {"rect": [12, 0, 16, 4]}, "holes": [{"rect": [1, 1, 2, 2]}]}
                ]
            },
            "G005",
            "components",
        ),
        # sharing an edge with the main piece (the pillar's side): one piece, not two
        ({"workspace.components": [{"boundary": {"rect": [4, 5, 5, 6]}}]}, "M101", "components"),
        (
            {
                "workspace.components": [
                    {"boundary": {"rect": [12, 0, 16, 4]}},
                    {"boundary": {"rect": [16, 1, 17, 2]}},
                ]
            },
            "M101",
            "components",
        ),
        ({"robot": {"start": [20, 20]}}, "G009", "robot"),
        ({"robot": {"start": [4.5, 4.5]}}, "G010", "robot"),  # in the pillar, not the pocket
        ({"regions": {"x": {"rect": [9, 9, 13, 11]}}}, "G007", "regions"),
        ({"regions": {"x": {"rect": [4.2, 4.2, 4.8, 4.8]}}}, "G008", "regions"),
        (
            {"workspace.components": [{"boundary": [[20, 0], [21, 1], [21, 0], [20, 1]]}]},
            "G004",
            "components",
        ),
    ],
)
def test_bad_components_get_diagnostics(change: dict[str, Any], code: str, line_of: str) -> None:
    document = rooms(**change)
    if "workspace.components" in change:
        document["regions"] = {"a": {"rect": [1, 1, 2, 2]}, "b": {"rect": [8.5, 8.5, 9.5, 9.5]}}
    if "regions" in change:
        document["task"] = ["visit x"]
    source = text(document)
    problems = check_text(source, "m.yaml")
    assert [p.code for p in problems if p.severity == "error"] == [code], problems
    line = next(i for i, t in enumerate(source.splitlines(), 1) if t.lstrip().startswith(line_of))
    assert problems[0].line is not None
    assert problems[0].line >= line


def test_pieces_may_touch_and_the_start_may_be_in_any_piece() -> None:
    touching = rooms(
        **{
            "workspace.components": [
                {"boundary": {"rect": [5, 5, 7, 7]}},
                {"boundary": {"rect": [10, 10, 12, 12]}},  # meets the room at a corner
            ],
            "robot": {"start": [6.0, 6.2]},
            "regions": {"pocket": {"rect": [5.5, 5.5, 6.5, 6.5]}, "a": {"rect": [1, 1, 2, 2]}},
            "task": ["visit pocket"],
        }
    )
    assert check_text(text(touching), "m.yaml") == []


def test_components_cannot_be_combined_with_a_map() -> None:
    document = rooms()
    document["workspace"] = {
        "map": "nowhere.yaml",
        "components": [{"boundary": {"rect": [0, 0, 1, 1]}}],
    }
    assert [p.code for p in check_text(text(document), "m.yaml")] == ["M014"]


# --- triangulation: disjoint meshes, one per piece -------------------------------------------


@st.composite
def multi_piece_missions(draw: st.DrawFn) -> Mission:
    """A room with a pillar, maybe a pocket in it, and rooms beside it (some touching corners)."""
    width = draw(st.integers(6, 10))
    pillar = rect(2.0, 2.0, width - 2.0, 4.0)
    components: list[Component] = []
    if draw(st.booleans()):
        components.append(Component(boundary=rect(2.5, 2.5, width - 2.5, 3.5)))
    x, top = float(width), 6.0
    for _ in range(draw(st.integers(0, 3))):
        touch = draw(st.booleans())  # meet the previous room at its top right corner
        x0 = x if touch else x + draw(st.floats(0.5, 2.0))
        w = draw(st.floats(1.0, 3.0))
        y0 = top if touch else draw(st.floats(0.0, 4.0))
        top = y0 + 2.0
        holes: tuple[Ring, ...] = ()
        if w > 2.0 and draw(st.booleans()):
            holes = (rect(x0 + 0.5, y0 + 0.5, x0 + 1.0, y0 + 1.0),)
        components.append(Component(boundary=rect(x0, y0, x0 + w, y0 + 2.0), holes=holes))
        x = x0 + w
    min_angle = draw(st.sampled_from([None, 20.0]))
    return Mission(
        name="pieces",
        workspace=Workspace(
            boundary=rect(0, 0, width, 6), holes=(pillar,), components=tuple(components)
        ),
        regions=(Region(name="r", polygon=rect(0.5, 0.5, 1.5, 1.5)),),
        robot=Robot(start=(0.2, 0.2)),
        formula=TRUE,
        options=Options(min_angle=min_angle),
    )


def test_obstacle_space_enclosed_by_pieces_touching_at_corners_gets_no_triangle() -> None:
    """Four triangles touching at the corners of a diamond: the diamond is no piece's hole."""
    corners = [
        ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)),
        ((1.0, 0.0), (2.0, 0.0), (2.0, 1.0)),
        ((2.0, 1.0), (2.0, 2.0), (1.0, 2.0)),
        ((1.0, 2.0), (0.0, 2.0), (0.0, 1.0)),
    ]
    mission = Mission(
        name="diamond",
        workspace=Workspace(
            boundary=corners[0], components=tuple(Component(boundary=c) for c in corners[1:])
        ),
        regions=(Region(name="r", polygon=((0.1, 0.1), (0.4, 0.1), (0.1, 0.4))),),
        robot=Robot(start=(0.2, 0.2)),
        formula=TRUE,
        options=Options(min_angle=None),
    )
    abstraction = build_abstraction(mission)
    triangles = [Polygon(c) for c in abstraction.vertices[abstraction.triangles]]
    assert sum(t.area for t in triangles) == pytest.approx(4 * 0.5)
    diamond = Polygon([(1, 0), (2, 1), (1, 2), (0, 1)])
    assert all(t.intersection(diamond).area < 1e-12 for t in triangles)


def piece_polygons(mission: Mission) -> list[Any]:
    return [
        Polygon(p.boundary).difference(shapely.union_all([Polygon(h) for h in p.holes]))
        if p.holes
        else Polygon(p.boundary)
        for p in mission.workspace.pieces
    ]


@settings(deadline=None, max_examples=30)
@given(multi_piece_missions())
def test_each_piece_gets_its_own_mesh(mission: Mission) -> None:
    abstraction = build_abstraction(mission)
    pieces = piece_polygons(mission)
    triangles = [Polygon(c) for c in abstraction.vertices[abstraction.triangles]]
    # the triangles tile exactly the union of the pieces' free space
    total = sum(p.area for p in pieces)
    assert sum(t.area for t in triangles) == pytest.approx(total, rel=1e-9)
    owner = []
    for triangle in triangles:
        centre = triangle.centroid
        inside = [k for k, p in enumerate(pieces) if p.covers(centre)]
        assert len(inside) == 1
        owner.append(inside[0])
    # neighbours (a shared edge) always lie in the same piece: no motion between pieces
    owners = np.asarray(owner)
    for index, row in enumerate(abstraction.neighbors):
        for other in row:
            if other >= 0:
                assert owners[other] == owners[index]
    # and every piece is one connected mesh (each piece here is connected)
    for k in range(len(pieces)):
        assert len(set(abstraction.component[owners == k].tolist())) == 1
    assert len(set(abstraction.component.tolist())) == len(pieces)


# --- planning, verifying, exporting --------------------------------------------------------


def test_plans_stay_in_the_robot_piece_and_verify(tmp_path: Path) -> None:
    source = tmp_path / "rooms.yaml"
    source.write_text(text(ROOMS))
    code, _, err = run("compile", str(source), "-o", str(tmp_path / "out"))
    assert code == 0, err
    # the unreachable regions are named with the piece they lie in, in one warning
    assert "warning[A011]: 2 regions are not reachable from the start: " in err
    assert "far (workspace component 1)" in err
    assert "pocket (workspace component 0)" in err
    assert err.count("A011") == 1
    trace = json.loads((tmp_path / "out" / "trace.json").read_text())
    assert validation_errors(trace, "trace") == []
    assert len(trace["workspace"]["components"]) == 2
    main_piece = piece_polygons(load_mission_text(text(ROOMS), "rooms.yaml"))[0]
    for _, x, y in trace["points"]:
        assert main_piece.covers(Point(x, y))


def test_a_plan_inside_a_pocket() -> None:
    document = rooms(
        **{"robot": {"start": [5.2, 5.2]}, "task": ["visit pocket"]},
    )
    compiled = compile_mission(document)
    pocket = Polygon(rect(5, 5, 7, 7))
    points = compiled.artifacts["trace.json"]["points"]
    assert all(pocket.covers(Point(x, y)) for _, x, y in points)
    assert compiled.artifacts["verdict.json"]["verdict"] == "satisfied"


@pytest.mark.parametrize(("start", "task"), [([0.5, 0.5], "visit far"), ([15.5, 0.5], "visit a")])
def test_a_region_in_another_piece_has_no_plan_and_says_why(start: list[float], task: str) -> None:
    document = rooms(**{"robot": {"start": start}, "task": [task]})
    with pytest.raises(NoPlanError) as caught:
        compile_mission(document)
    words = " ".join(f"{d.message} {d.hint}" for d in caught.value.diagnostics)
    assert "separate pieces of free space" in words
    assert task.split()[1] in words


def verify_points(points: list[list[float]]) -> Any:
    mission = load_mission_text(text(ROOMS), "rooms.yaml")
    document = {
        "format": "tlmpc.trace/1",
        "ltl": "true",
        "regions": {r.name: [list(p) for p in r.polygon] for r in mission.regions},
        "workspace": mission.workspace.to_json(),
        "points": points,
        "loop_start": None,
    }
    return verify_trace(from_document(document, file="t.json", convention=None))


def test_the_verifier_counts_every_piece_as_workspace() -> None:
    in_pocket = verify_points([[0, 5.2, 5.2], [1, 6.8, 6.8]])
    assert in_pocket.workspace_violation is None
    in_far = verify_points([[0, 12.5, 0.5], [1, 15.5, 0.5], [2, 15.5, 3.5]])
    assert in_far.workspace_violation is None
    # from the room into the pocket: through the pillar
    across = verify_points([[0, 3, 3], [1, 6, 6]])
    assert across.workspace_violation is not None
    assert "entered a hole" in across.workspace_violation.message
    # into a hole of a further piece
    hole = verify_points([[0, 12.5, 0.5], [1, 13.5, 1.5]])
    assert hole.workspace_violation is not None
    assert "entered a hole" in hole.workspace_violation.message
    # between the two rooms: outside every piece
    gap = verify_points([[0, 9, 1], [1, 13, 0.5]])
    assert gap.workspace_violation is not None


def test_geojson_has_every_piece(tmp_path: Path) -> None:
    source = tmp_path / "rooms.yaml"
    source.write_text(text(ROOMS))
    assert run("compile", str(source), "-o", str(tmp_path / "out"))[0] == 0
    code, out, err = run("export-plan", str(tmp_path / "out"), "--format", "geojson")
    assert code == 0, err
    workspace = json.loads(out)["features"][0]["geometry"]
    assert workspace["type"] == "MultiPolygon"
    geometry = shape(workspace)
    assert geometry.is_valid
    assert geometry.area == pytest.approx(free_area_oracle(ROOMS).area)
    for polygon in workspace["coordinates"]:  # RFC 7946: outer rings counter-clockwise
        assert shapely.LinearRing(polygon[0]).is_ccw
        assert all(not shapely.LinearRing(h).is_ccw for h in polygon[1:])


def test_plots_draw_every_piece(tmp_path: Path) -> None:
    source = tmp_path / "rooms.yaml"
    source.write_text(text(ROOMS))
    assert run("compile", str(source), "-o", str(tmp_path / "out"))[0] == 0
    svg = (tmp_path / "out" / "plan.svg").read_text()
    plain = rooms()
    del plain["workspace"]["components"]
    plain["regions"] = {"a": {"rect": [1, 1, 2, 2]}, "b": {"rect": [8.5, 8.5, 9.5, 9.5]}}
    source.write_text(text(plain))
    assert run("compile", str(source), "-o", str(tmp_path / "plain"))[0] == 0
    without = (tmp_path / "plain" / "plan.svg").read_text()
    # two more white pieces, and the further piece's hole, are painted
    assert svg.count('fill="#fff"') >= without.count('fill="#fff"') + 1
    assert svg.count('fill="#9a9a9a"') >= without.count('fill="#9a9a9a"') + 1
