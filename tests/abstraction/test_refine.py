"""Fan splits for U-turns keep the mesh conforming and observation-preserving."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon
from test_abstraction_props import workspaces

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.model import Abstraction
from tlmpc.abstraction.refine import split_triangles
from tlmpc.mission.model import Mission


def _check_mesh(a: Abstraction, mission: Mission) -> None:
    corners = a.vertices[a.triangles]
    signed = 0.5 * (
        (corners[:, 1, 0] - corners[:, 0, 0]) * (corners[:, 2, 1] - corners[:, 0, 1])
        - (corners[:, 2, 0] - corners[:, 0, 0]) * (corners[:, 1, 1] - corners[:, 0, 1])
    )
    assert np.all(signed > 0), "counter-clockwise, positive area"
    for t in range(a.num_triangles):
        for i in range(3):
            n = int(a.neighbors[t, i])
            if n < 0:
                continue
            # Conforming: the neighbour across edge i holds exactly that edge's two vertices.
            edge = {int(a.triangles[t, (i + 1) % 3]), int(a.triangles[t, (i + 2) % 3])}
            assert edge <= set(a.triangles[n].tolist())
            assert int(a.neighbors[n].tolist().index(t)) >= 0
    centroids = corners.mean(axis=1)
    for region in mission.regions:
        shape = Polygon(region.polygon)
        inside = np.array([region.name in a.labels(t) for t in range(a.num_triangles)])
        assert np.array_equal(inside, shapely.contains_xy(shape, *centroids.T))


@settings(deadline=None, max_examples=30)
@given(workspaces(), st.data())
def test_fan_splits_keep_the_mesh_conforming_and_labels_exact(
    mission: Mission, data: st.DataObject
) -> None:
    built = build_abstraction(mission)
    chosen = data.draw(
        st.lists(st.integers(0, built.num_triangles - 1), min_size=1, max_size=6, unique=True)
    )
    refined = split_triangles(built, chosen, mission.robot.start)
    assert refined.num_triangles == built.num_triangles + 2 * len(chosen)
    _check_mesh(refined, mission)
    # The same area is covered, and untouched triangles keep their index and corners.
    area = sum(Polygon(c).area for c in refined.vertices[refined.triangles])
    assert area == pytest.approx(sum(Polygon(c).area for c in built.vertices[built.triangles]))
    for t in set(range(built.num_triangles)) - set(chosen):
        assert np.array_equal(
            refined.vertices[refined.triangles[t]], built.vertices[built.triangles[t]]
        )
    # Each split triangle became a fan of three, mutually adjacent around one new vertex.
    for k, t in enumerate(sorted(chosen)):
        fan = {t, built.num_triangles + 2 * k, built.num_triangles + 2 * k + 1}
        for s in fan:
            assert fan - {s} <= set(refined.neighbors[s].tolist())
        shared = set.intersection(*(set(refined.triangles[s].tolist()) for s in fan))
        assert len(shared) == 1
        assert next(iter(shared)) >= len(built.vertices)
    start = Point(mission.robot.start)
    assert Polygon(refined.corners(refined.start)).distance(start) < 1e-9


def test_start_never_lies_on_a_spoke() -> None:
    from test_abstraction_props import mission_of, rect

    # The start at the centroid direction of a corner: on the centroid's spoke.
    mission = mission_of(rect(0, 0, 3, 3), [], {}, (0.5, 0.5))
    built = build_abstraction(mission)
    start = built.start
    corners = built.corners(start)
    centroid = corners.mean(axis=0)
    on_spoke = tuple((corners[0] + centroid) / 2)
    refined = split_triangles(built, [start], on_spoke)
    assert Polygon(refined.corners(refined.start)).contains(Point(on_spoke))
