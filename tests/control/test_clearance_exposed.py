"""Exposed vertices (a region's own boundary) against shapely's distance, vertex by vertex."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.model import Abstraction
from tlmpc.control.clearance import TOUCH, exposed_vertices
from tlmpc.mission import load_mission

SPECS = Path(__file__).parents[2] / "specs"


def _mesh(name: str) -> Abstraction:
    return build_abstraction(load_mission(SPECS / name))


def _by_definition(
    abstraction: Abstraction, candidates: list[int], relevant: set[str] | None = None
) -> frozenset[int]:
    """Each candidate whose distance to the boundary of a region labelling a triangle around
    a candidate (one of ``relevant``) is within TOUCH of the mesh's extent (shapely's
    distance, one point at a time)."""
    extent = float(np.ptp(abstraction.vertices, axis=0).max())
    around = np.flatnonzero(np.isin(abstraction.triangles, candidates).any(axis=1))
    names = {
        n
        for t in around.tolist()
        for n in abstraction.labels(t)
        if relevant is None or n in relevant
    }
    outlines = shapely.MultiLineString(
        [
            shapely.Polygon(abstraction.regions[n]).exterior
            for n in sorted(names)
            if n in abstraction.regions
        ]
    )
    found = set()
    if not names:
        return frozenset()
    for vertex in candidates:
        point = shapely.Point(abstraction.vertices[vertex])
        if shapely.distance(point, outlines) <= TOUCH * extent:
            found.add(vertex)
    return frozenset(found)


@pytest.mark.parametrize("spec", ["example1.yaml", "example8.yaml", "reach-avoid.yaml"])
def test_label_boundary_vertices_of_shipped_maps(spec: str) -> None:
    mesh = _mesh(spec)
    letters = mesh.letter_of
    # vertices where labels change: on an edge between triangles of different letters
    boundary = set()
    for t in range(mesh.num_triangles):
        for i in range(3):
            n = int(mesh.neighbors[t, i])
            if n >= 0 and letters[n] != letters[t]:
                corners = mesh.triangles[t].tolist()
                boundary.update(corners[:i] + corners[i + 1 :])
    candidates = sorted(boundary)
    assert candidates
    assert exposed_vertices(mesh, candidates) == _by_definition(mesh, candidates)


@settings(max_examples=max(10, settings().max_examples // 5), deadline=None)
@given(st.lists(st.integers(0, 10**6), min_size=1, max_size=40))
def test_any_vertices_of_example1(picks: list[int]) -> None:
    mesh = _mesh("example1.yaml")
    candidates = sorted({p % len(mesh.vertices) for p in picks})
    assert exposed_vertices(mesh, candidates) == _by_definition(mesh, candidates)


@settings(max_examples=max(10, settings().max_examples // 5), deadline=None)
@given(st.lists(st.integers(0, 10**6), min_size=1, max_size=60), st.sets(st.integers(0, 3)))
def test_only_the_regions_a_task_names_expose_their_boundary(
    picks: list[int], named: set[int]
) -> None:
    """Example 1's four regions, of which a random subset is named: a vertex on the boundary
    of an unnamed region only is not exposed."""
    mesh = _mesh("example1.yaml")
    candidates = sorted({p % len(mesh.vertices) for p in picks})
    relevant = {f"p{k + 1}" for k in named}
    assert exposed_vertices(mesh, candidates, relevant) == _by_definition(
        mesh, candidates, relevant
    )
