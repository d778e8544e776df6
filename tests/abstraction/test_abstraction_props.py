"""The transition system D: observation preservation, areas, neighbours (properties)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon

from tlmpc.abstraction import (
    abstraction_diagnostics,
    abstraction_from_json,
    abstraction_to_json,
    build_abstraction,
    locate,
)
from tlmpc.abstraction.model import Abstraction
from tlmpc.abstraction.resolution import subgrid_problems
from tlmpc.base.errors import InvalidInputError
from tlmpc.io.schema_check import validation_errors
from tlmpc.ltl.ast import TRUE
from tlmpc.mission import load_mission
from tlmpc.mission.model import Mission, Options, Region, Robot, Workspace

ROOT = Path(__file__).resolve().parents[2]


def rect(x0: float, y0: float, x1: float, y1: float) -> tuple[tuple[float, float], ...]:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


def mission_of(boundary, holes, regions, start, options=None) -> Mission:  # type: ignore[no-untyped-def]
    return Mission(
        name="t",
        workspace=Workspace(boundary=boundary, holes=tuple(holes)),
        regions=tuple(Region(name=n, polygon=p) for n, p in regions.items()),
        robot=Robot(start=start),
        formula=TRUE,
        options=options or Options(),
    )


@st.composite
def workspaces(draw: st.DrawFn) -> Mission:
    """A box with up to two holes and up to four overlapping regions (convex or star)."""
    width = draw(st.integers(6, 12))
    height = draw(st.integers(5, 10))
    holes = []
    if draw(st.booleans()):
        holes.append(rect(1.0, 1.0, 2.0, 2.5))
    if draw(st.booleans()):
        holes.append(rect(width - 2.5, height - 2.0, width - 1.5, height - 1.0))
    regions = {}
    for k in range(draw(st.integers(1, 4))):
        # Regions may stick out of the boundary, lie beyond it, or sit in a hole.
        x0 = draw(st.floats(-1.0, width + 1.0))
        y0 = draw(st.floats(-1.0, height - 2.0))
        w = draw(st.floats(0.5, 3.0))
        h = draw(st.floats(0.5, 3.0))
        if draw(st.booleans()):
            regions[f"r{k}"] = rect(x0, y0, x0 + w, y0 + h)
        else:  # a triangle-ish star polygon
            regions[f"r{k}"] = ((x0, y0), (x0 + w, y0 + h / 3), (x0 + w / 2, y0 + h))
    start = (width - 0.1, 0.1)
    min_angle = draw(st.sampled_from([None, 20.0]))
    mission = mission_of(
        rect(0, 0, width, height), holes, regions, start, Options(min_angle=min_angle)
    )
    # Features closer than the snapping grid are refused (G030/G031, tests/abstraction/
    # test_resolution.py); about one drawn map in thousands has one.
    assume(not subgrid_problems(mission))
    return mission


def _triangle_polygons(a: Abstraction) -> list[Polygon]:
    return [Polygon(c) for c in a.vertices[a.triangles]]


@settings(deadline=None, max_examples=40)
@given(workspaces())
def test_observation_preserving(mission: Mission) -> None:
    a = build_abstraction(mission)
    triangles = _triangle_polygons(a)
    centroids = a.vertices[a.triangles].mean(axis=1)
    for region in mission.regions:
        shape = Polygon(region.polygon)
        inside = np.array([region.name in a.labels(t) for t in range(a.num_triangles)])
        centroid_in = shapely.contains_xy(shape, centroids[:, 0], centroids[:, 1])
        assert np.array_equal(inside, centroid_in)
        for t, polygon in enumerate(triangles):
            overlap = polygon.intersection(shape).area
            # Wholly inside or wholly outside, never crossed by the region boundary (up to
            # the snapping grid, a billionth of the workspace's extent).
            assert overlap == pytest.approx(polygon.area if inside[t] else 0.0, abs=1e-7), (
                region,
                t,
            )


@settings(deadline=None, max_examples=40)
@given(workspaces())
def test_areas_sum_to_the_free_area_and_none_is_degenerate(mission: Mission) -> None:
    a = build_abstraction(mission)
    free = Polygon(mission.workspace.boundary)
    for hole in mission.workspace.holes:
        free = free.difference(Polygon(hole))
    corners = a.vertices[a.triangles]
    signed = 0.5 * (
        (corners[:, 1, 0] - corners[:, 0, 0]) * (corners[:, 2, 1] - corners[:, 0, 1])
        - (corners[:, 2, 0] - corners[:, 0, 0]) * (corners[:, 1, 1] - corners[:, 0, 1])
    )
    assert np.all(signed > 0), "triangles are counter-clockwise with positive area"
    assert signed.sum() == pytest.approx(free.area, rel=1e-9)
    for hole in mission.workspace.holes:
        hole_shape = Polygon(hole)
        for polygon in _triangle_polygons(a):
            assert polygon.intersection(hole_shape).area <= 1e-12


@settings(deadline=None, max_examples=40)
@given(workspaces())
def test_neighbours_are_symmetric_and_share_one_edge(mission: Mission) -> None:
    a = build_abstraction(mission)
    for t in range(a.num_triangles):
        for i in range(3):
            n = int(a.neighbors[t, i])
            if n < 0:
                continue
            assert t in a.neighbors[n].tolist()
            edge = {int(a.triangles[t, (i + 1) % 3]), int(a.triangles[t, (i + 2) % 3])}
            shared = edge & set(a.triangles[n].tolist())
            assert len(shared) == 2
            p, q = a.vertices[sorted(shared)]
            assert np.linalg.norm(p - q) > 0


def test_paper_example8_has_the_papers_9250_triangles() -> None:
    a = build_abstraction(load_mission(ROOT / "specs" / "example8.yaml"))
    assert a.num_triangles == 9250
    assert len(a.letters) == 34 * 34 + 1


def test_quality_options_refine() -> None:
    base = mission_of(
        rect(0, 0, 10, 4), [], {"a": rect(1, 1, 2, 2)}, (5, 2), Options(min_angle=None)
    )
    coarse = build_abstraction(base)
    fine = build_abstraction(
        mission_of(
            rect(0, 0, 10, 4),
            [],
            {"a": rect(1, 1, 2, 2)},
            (5, 2),
            Options(min_angle=30.0, max_area=0.5),
        )
    )
    assert fine.num_triangles > coarse.num_triangles
    assert fine.stats["min_angle_deg"] >= 30.0 - 1e-6
    assert (fine.vertices[fine.triangles].max(axis=1) >= 0).all()


def test_overlapping_regions_are_split_at_their_intersections() -> None:
    mission = mission_of(
        rect(0, 0, 6, 6), [], {"a": rect(1, 1, 4, 4), "b": rect(2, 2, 5, 5)}, (0.5, 0.5)
    )
    a = build_abstraction(mission)
    assert {("a",), ("b",), ("a", "b"), ()} <= set(a.letters)


def test_hole_touching_the_boundary_and_a_region_sharing_a_hole_edge() -> None:
    mission = mission_of(rect(0, 0, 6, 4), [rect(2, 0, 3, 2)], {"a": rect(3, 0, 4, 1)}, (0.5, 3))
    a = build_abstraction(mission)
    free = Polygon(rect(0, 0, 6, 4)).difference(Polygon(rect(2, 0, 3, 2)))
    assert sum(p.area for p in _triangle_polygons(a)) == pytest.approx(free.area)


def test_start_and_locate() -> None:
    mission = mission_of(rect(0, 0, 4, 4), [], {"a": rect(1, 1, 2, 2)}, (1.5, 1.5))
    a = build_abstraction(mission)
    assert a.labels(a.start) == ("a",)
    assert locate(a, (10, 10)) == -1


def test_start_outside_is_an_error() -> None:
    mission = mission_of(rect(0, 0, 4, 4), [rect(1, 1, 3, 3)], {"a": rect(0, 0, 1, 1)}, (2, 2))
    with pytest.raises(InvalidInputError) as caught:
        build_abstraction(mission)
    assert caught.value.diagnostics[0].code == "A002"
    assert caught.value.diagnostics[0].path == "$.robot.start"  # placed at it in the file


def test_unreachable_region_is_reported() -> None:
    # a wall of holes splits the box in two
    mission = mission_of(
        rect(0, 0, 6, 4), [rect(2, 0, 3, 4)], {"far": rect(4, 1, 5, 2)}, (0.5, 0.5)
    )
    a = build_abstraction(mission)
    warnings = abstraction_diagnostics(a, mission)
    assert [w.code for w in warnings] == ["A011"]
    assert "far" in warnings[0].message
    assert a.stats["components"] == 2


@given(st.integers(2, 30))
@settings(max_examples=6, deadline=None)
def test_many_unreachable_regions_are_one_warning(count: int) -> None:
    # a wall of holes; behind it, `count` regions in a row: one A011 naming each of them
    regions = {f"r{k}": rect(4 + 0.1 * k, 1, 4.05 + 0.1 * k, 2) for k in range(count)}
    mission = mission_of(rect(0, 0, 8, 4), [rect(2, 0, 3, 4)], regions, (0.5, 0.5))
    warnings = abstraction_diagnostics(build_abstraction(mission), mission)
    assert [w.code for w in warnings] == ["A011"]
    message = warnings[0].message
    assert message.startswith(f"{count} regions are not reachable from the start: ")
    shown = [f"r{k}" for k in range(count)][:12]
    assert all(
        f"{name}," in message or f"{name} " in message or f"{name};" in message for name in shown
    )
    if count > 12:
        assert f"and {count - 12} more" in message


def test_artifact_round_trip_and_schema() -> None:
    a = build_abstraction(load_mission(ROOT / "specs" / "example6.yaml"))
    document = abstraction_to_json(a)
    assert validation_errors(document, "abstraction") == []
    back = abstraction_from_json(document)
    assert back == a
    for name in ("vertices", "triangles", "neighbors", "letter_of", "component"):
        assert np.array_equal(getattr(back, name), getattr(a, name))


@pytest.mark.parametrize(
    ("holes", "region"),
    [
        ([rect(2, 2, 6, 6)], rect(3, 3, 4, 4)),  # inside a hole
        ([], rect(12, 3, 14, 4)),  # beyond the boundary
        ([rect(2, 2, 6, 6)], rect(1, 1, 7, 7)),  # encloses a hole
    ],
)
def test_region_rings_outside_the_free_space_are_no_segments(
    holes: list[tuple[tuple[float, float], ...]], region: tuple[tuple[float, float], ...]
) -> None:
    mission = mission_of(rect(0, 0, 10, 10), holes, {"a": region}, (8.5, 8.5))
    a = build_abstraction(mission)
    free = Polygon(rect(0, 0, 10, 10))
    for hole in holes:
        free = free.difference(Polygon(hole))
    assert sum(p.area for p in _triangle_polygons(a)) == pytest.approx(free.area, rel=1e-12)
    expected = Polygon(region).intersection(free).area
    labelled = sum(p.area for t, p in enumerate(_triangle_polygons(a)) if "a" in a.labels(t))
    assert labelled == pytest.approx(expected, abs=1e-12)
    codes = [d.code for d in abstraction_diagnostics(a, mission)]
    assert codes == ([] if expected > 0 else ["A010"])


@settings(deadline=None, max_examples=40)
@given(workspaces())
def test_the_pslg_is_the_noded_linework_each_point_once(mission: Mission) -> None:
    """Its vertices are the distinct points of the linework (distinct on the snapping grid,
    in grid order), its segments the distinct pieces between them, and together they draw
    exactly the free space's boundary and the region boundaries inside the free space."""
    import numpy as np
    import shapely

    from tlmpc.abstraction.triangulate import free_space, pslg
    from tlmpc.mission.resolution import grid_size

    vertices, segments, _, regions = pslg(mission)
    grid = grid_size(mission)
    free = free_space(mission, grid)
    keys = np.round((vertices - np.array(free.bounds[:2])) / grid).astype(np.int64)
    assert [tuple(k) for k in keys.tolist()] == sorted({tuple(k) for k in keys.tolist()})
    assert len({tuple(e) for e in segments.tolist()}) == len(segments)
    assert all(a < b for a, b in segments.tolist())
    drawn = shapely.union_all(shapely.linestrings(vertices[segments]))
    inside = [shapely.intersection(shapely.boundary(r), free) for r in regions]
    # on the grid: a region's side within a millionth of a step of the boundary's is that side
    expected = shapely.union_all([shapely.boundary(free), *inside], grid_size=grid)
    assert shapely.hausdorff_distance(drawn, expected) <= 4 * grid
    assert shapely.length(drawn) == pytest.approx(shapely.length(expected), rel=1e-9, abs=grid)
    used = np.unique(segments)
    assert used.tolist() == list(range(len(vertices)))  # every vertex ends some segment
