"""Georeferenced GeoJSON: the map's straight edges, not only its vertices, land where they are.

GeoJSON draws a segment straight in longitude and latitude (RFC 7946 §3.1.1); a map's straight
edge (a line of the ellipsoid's tangent plane at the origin) is curved there, by metres over
kilometres.  The export adds points along each edge until every written segment lies within
a millimetre of the map's edge.  The oracle is an inverse mapping written here (a point of the
ellipsoid back along its normal onto the tangent plane, then into the map's axes): points
along every written segment, mapped back, must lie on the map's polygon boundary or on the
trajectory.
"""

from __future__ import annotations

import itertools
import json
import math
from typing import Any

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Polygon

from tlmpc.base.errors import UsageError
from tlmpc.exports import georeference
from tlmpc.exports.formats import geojson
from tlmpc.exports.georeference import Georeference
from tlmpc.exports.plan import Plan, waypoints

A = 6378137.0
E2 = (1.0 / 298.257223563) * (2.0 - 1.0 / 298.257223563)


def _ecef(latitude: float, longitude: float) -> np.ndarray:
    phi, lam = math.radians(latitude), math.radians(longitude)
    n = A / math.sqrt(1.0 - E2 * math.sin(phi) ** 2)
    return np.array(
        [
            n * math.cos(phi) * math.cos(lam),
            n * math.cos(phi) * math.sin(lam),
            n * (1.0 - E2) * math.sin(phi),
        ]
    )


def _normal(latitude: float, longitude: float) -> np.ndarray:
    phi, lam = math.radians(latitude), math.radians(longitude)
    return np.array([math.cos(phi) * math.cos(lam), math.cos(phi) * math.sin(lam), math.sin(phi)])


def _to_map(reference: Georeference, longitude: float, latitude: float) -> tuple[float, float]:
    """The map point whose normal foot is (longitude, latitude): along the normal there back
    onto the tangent plane at the origin, then east/north turned by -yaw."""
    origin = _ecef(reference.latitude, reference.longitude)
    up = _normal(reference.latitude, reference.longitude)
    lam, phi = math.radians(reference.longitude), math.radians(reference.latitude)
    east = np.array([-math.sin(lam), math.cos(lam), 0.0])
    north = np.array(
        [-math.sin(phi) * math.cos(lam), -math.sin(phi) * math.sin(lam), math.cos(phi)]
    )
    foot = _ecef(latitude, longitude)
    along = _normal(latitude, longitude)
    on_plane = foot + along * float(np.dot(origin - foot, up) / np.dot(along, up))
    e, n = float(np.dot(on_plane - origin, east)), float(np.dot(on_plane - origin, north))
    turn = math.radians(reference.yaw)
    return e * math.cos(turn) + n * math.sin(turn), -e * math.sin(turn) + n * math.cos(turn)


def _plan(size: float) -> Plan:
    """A square map ``size`` metres wide with a hole and a region, and a trajectory of long
    straight steps along the map's diagonal and back."""
    ring = ((0.0, 0.0), (size, 0.0), (size, size), (0.0, size))
    hole = ((0.6 * size, 0.1 * size), (0.9 * size, 0.1 * size), (0.75 * size, 0.4 * size))
    steps = np.linspace(0.05, 0.95, 5) * size
    samples = np.array([[float(i), x, x] for i, x in enumerate([*steps, *steps[::-1]])])
    return Plan(
        samples=samples,
        loop_start=None,
        name="square",
        boundary=ring,
        holes=(hole,),
        regions={
            "dock": ((0.1 * size, 0.5 * size), (0.4 * size, 0.5 * size), (0.25 * size, 0.9 * size))
        },
        formula="F dock",
    )


def _export(plan: Plan, reference: Georeference) -> dict[str, Any]:
    points, loop = waypoints(plan)
    document: dict[str, Any] = json.loads(geojson(plan, points, loop, reference))
    return document


def _rings(geometry: dict[str, Any]) -> list[list[list[float]]]:
    polygons = (
        [geometry["coordinates"]] if geometry["type"] == "Polygon" else geometry["coordinates"]
    )
    return [ring for polygon in polygons for ring in polygon]


def _along(ring: list[list[float]]) -> list[tuple[float, float]]:
    """Points a quarter, a half and three quarters along each written segment."""
    return [
        (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]))
        for a, b in itertools.pairwise(ring)
        for f in (0.25, 0.5, 0.75)
    ]


@pytest.mark.parametrize(
    ("latitude", "longitude", "yaw"),
    [(60.0, 10.0, 30.0), (-45.0, -70.0, 0.0), (0.0, 100.0, -120.0), (85.0, 20.0, 10.0)],
)
def test_written_edges_lie_on_the_maps_edges(latitude: float, longitude: float, yaw: float) -> None:
    plan = _plan(10_000.0)
    reference = Georeference(latitude, longitude, yaw)
    features = _export(plan, reference)["features"]
    edges = {
        "workspace": shapely.Polygon(plan.boundary, plan.holes).boundary,
        "region": Polygon(plan.regions["dock"]).boundary,
    }
    for feature in features:
        kind = feature["properties"]["kind"]
        if kind not in edges:
            continue
        for ring in _rings(feature["geometry"]):
            worst = max(
                edges[kind].distance(shapely.Point(_to_map(reference, *p))) for p in _along(ring)
            )
            assert worst < 2e-3, (kind, worst)
    (trajectory,) = [f for f in features if f["properties"]["kind"] == "trajectory"]
    line = LineString(plan.samples[:, 1:])
    coordinates = trajectory["geometry"]["coordinates"]
    worst = max(line.distance(shapely.Point(_to_map(reference, *p))) for p in _along(coordinates))
    assert worst < 2e-3
    # the added points' times are parallel to the points: each point is where the trajectory
    # (straight at constant speed between samples) is at its time
    times = trajectory["properties"]["times"]
    assert len(times) == len(coordinates) >= len(plan.samples)
    assert set(plan.samples[:, 0].tolist()) <= set(times)
    for time, point in zip(times, coordinates, strict=True):
        expected = [np.interp(time, plan.samples[:, 0], plan.samples[:, axis]) for axis in (1, 2)]
        assert math.dist(_to_map(reference, *point), expected) < 2e-3


def test_a_small_map_is_written_as_before() -> None:
    """A room-sized map's edges are straight within the tolerance: no point is added."""
    plan = _plan(20.0)
    features = _export(plan, Georeference(47.3, 8.5, 30.0))["features"]
    (workspace,) = [f for f in features if f["properties"]["kind"] == "workspace"]
    assert [len(ring) for ring in _rings(workspace["geometry"])] == [5, 4]
    (trajectory,) = [f for f in features if f["properties"]["kind"] == "trajectory"]
    assert trajectory["properties"]["times"] == plan.samples[:, 0].tolist()


def test_a_map_around_a_pole_is_refused() -> None:
    # the map's point (5, 5) is the North Pole: 7.07 m north of the origin along x turned 45°
    with pytest.raises(UsageError) as raised:
        _export(_plan(10.0), Georeference(90.0 - 7.0710678 / 111_694.0, 0.0, 45.0))
    (diagnostic,) = raised.value.diagnostics
    assert diagnostic.code == "M088"
    assert diagnostic.file == "--georeference"


def test_the_points_added_are_bounded(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(georeference, "MAX_ADDED_POINTS", 10)
    with pytest.raises(UsageError) as raised:
        _export(_plan(10_000.0), Georeference(60.0, 10.0, 0.0))
    (diagnostic,) = raised.value.diagnostics
    assert diagnostic.code == "M087"
    assert diagnostic.hint
