"""The clearance measurement against its definition, evaluated point by point.

:func:`tlmpc.verify.clearance.measure` skips the samples outside a goal's bounding box and
builds only the one segment it reports a position on; the oracle here does neither: every
sample is tested against every region with a shapely point of its own, and the nearest
position is read off the full list of segments.  Both must give the same floats.
"""

from __future__ import annotations

import itertools

import numpy as np
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tlmpc.ltl.parser import parse_ltl
from tlmpc.verify.clearance import measure
from tlmpc.verify.trace_input import TraceInput

BOUNDARY = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]])
HOLE = np.array([[4.0, 4.0], [6.0, 4.0], [5.0, 6.0]])

coordinate = st.floats(min_value=0.0, max_value=10.0, allow_nan=False)


@st.composite
def triangles(draw: st.DrawFn) -> list[tuple[float, float]]:
    """A counter-clockwise triangle of positive area inside the boundary."""
    corners = [(draw(coordinate), draw(coordinate)) for _ in range(3)]
    (ax, ay), (bx, by), (cx, cy) = corners
    area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    if abs(area) < 1e-3:
        corners = [(1.0, 1.0), (3.0, 1.0), (2.0, 3.0)]
    elif area < 0:
        corners.reverse()
    return corners


def _oracle_depth(points: np.ndarray, ring: np.ndarray) -> tuple[float, tuple[float, float]] | None:
    region = shapely.Polygon(ring)
    best: tuple[float, tuple[float, float]] | None = None
    for x, y in points.tolist():
        point = shapely.Point(x, y)
        if not region.covers(point):
            continue
        depth = float(region.boundary.distance(point))
        if best is None or depth > best[0]:
            best = (depth, (x, y))
    return best


def _oracle_nearest(points: np.ndarray, target: shapely.Geometry) -> tuple[float, float, float]:
    parts = (
        [shapely.LineString([a, b]) for a, b in itertools.pairwise(points.tolist())]
        if len(points) > 1
        else [shapely.Point(points[0])]
    )
    distances = [float(shapely.distance(target, part)) for part in parts]
    worst = int(np.argmin(distances))
    a, _ = shapely.shortest_line(parts[worst], target).coords
    return distances[worst], float(a[0]), float(a[1])


@settings(max_examples=60, deadline=None)
@example(  # a sample on the goal's corner: on its bounding box's edge, covered, depth 0
    path=[(1.0, 1.0), (9.0, 9.0)],
    goals=[[(1.0, 1.0), (3.0, 1.0), (2.0, 3.0)]],
    avoid=[(7.0, 1.0), (9.0, 1.0), (8.0, 3.0)],
)
@given(
    path=st.lists(st.tuples(coordinate, coordinate), min_size=1, max_size=25),
    goals=st.lists(triangles(), min_size=1, max_size=3),
    avoid=triangles(),
)
def test_measure_agrees_with_the_pointwise_definition(
    path: list[tuple[float, float]],
    goals: list[list[tuple[float, float]]],
    avoid: list[tuple[float, float]],
) -> None:
    points = np.array(path, dtype=np.float64)
    names = [f"g{k}" for k in range(len(goals))]
    formula = parse_ltl(" & ".join([*(f"F {n}" for n in names), "G !bad"]))
    regions = {n: np.array(g, dtype=np.float64) for n, g in zip(names, goals, strict=True)}
    regions["bad"] = np.array(avoid, dtype=np.float64)
    trace = TraceInput(
        times=np.arange(len(points), dtype=np.float64),
        points=points,
        loop_start=None,
        formula=formula,
        regions=regions,
        boundary_polygon=BOUNDARY,
        holes=(HOLE,),
    )
    found = measure(trace)
    for name in names:
        expected = _oracle_depth(points, regions[name])
        if expected is None:
            assert name not in found.depth
        else:
            assert found.depth[name].achieved == expected[0]
            assert found.depth[name].position == expected[1]
    distance, x, y = _oracle_nearest(points, shapely.Polygon(regions["bad"]))
    assert found.forbidden["bad"] == distance
    assert found.forbidden_positions["bad"] == (x, y)
    walls = shapely.MultiLineString(
        [np.vstack([ring, ring[:1]]).tolist() for ring in (BOUNDARY, HOLE)]
    )
    distance, _, _ = _oracle_nearest(points, walls)
    # (measured through an STRtree near zero, the two may differ in the last digits)
    assert found.obstacles is not None
    assert abs(found.obstacles - distance) <= 1e-9
    # the nearest position on the path: ties (a path along a wall) may be broken either way
    assert found.obstacle_position is not None
    at = shapely.Point(found.obstacle_position)
    assert abs(float(walls.distance(at)) - distance) <= 1e-9
    assert (
        float(shapely.LineString(points.tolist()).distance(at)) <= 1e-9 if len(points) > 1 else True
    )
