"""GeoJSON in WGS 84: the map's plane is the tangent plane at the given origin, and each point
goes to the ellipsoid along its normal.

Oracle: the closed-form geodetic -> ECEF formula (no iteration): from the exported longitude
and latitude, the point of the ellipsoid normal that lies in the tangent plane must be the map
point, rotated by the yaw, to a micrometre.
"""

from __future__ import annotations

import io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import LineString, Point

from tlmpc.cli import main
from tlmpc.exports.georeference import Georeference, geodetic_to_ecef, to_lon_lat

MISSION = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 600, 400]}
  holes: [{rect: [250, 100, 350, 300]}]
regions:
  a: {rect: [50, 50, 150, 150]}
  b: {rect: [450, 250, 550, 350]}
robot: {start: [100, 300], max_speed: 5.0}
task: ["patrol a, b"]
"""


def _map_point(reference: Georeference, longitude: float, latitude: float) -> tuple[float, float]:
    """The oracle: where (longitude, latitude) sits in the map, through the tangent plane."""
    origin = np.array(geodetic_to_ecef(reference.latitude, reference.longitude))
    phi, lam = math.radians(reference.latitude), math.radians(reference.longitude)
    east = np.array([-math.sin(lam), math.cos(lam), 0.0])
    north = np.array(
        [-math.sin(phi) * math.cos(lam), -math.sin(phi) * math.sin(lam), math.cos(phi)]
    )
    up = np.cross(east, north)
    point = np.array(geodetic_to_ecef(latitude, longitude))
    p, q = math.radians(latitude), math.radians(longitude)
    normal = np.array([math.cos(p) * math.cos(q), math.cos(p) * math.sin(q), math.sin(p)])
    height = -float((point - origin) @ up) / float(normal @ up)
    in_plane = point + height * normal - origin
    e, n = float(in_plane @ east), float(in_plane @ north)
    turn = math.radians(reference.yaw)
    return e * math.cos(turn) + n * math.sin(turn), -e * math.sin(turn) + n * math.cos(turn)


@given(
    st.floats(-80, 80),
    st.floats(-180, 180),
    st.floats(-180, 180),
    st.floats(-5000, 5000),
    st.floats(-5000, 5000),
)
def test_map_points_go_to_the_ellipsoid_along_the_normal(
    latitude: float, longitude: float, yaw: float, x: float, y: float
) -> None:
    reference = Georeference(latitude, longitude, yaw)
    lon, lat = to_lon_lat(reference, x, y)
    back = _map_point(reference, lon, lat)
    assert math.dist(back, (x, y)) < 1e-6


def test_export_plan_writes_longitude_and_latitude(tmp_path: Path) -> None:
    mission = tmp_path / "m.yaml"
    mission.write_text(MISSION)
    out = tmp_path / "out"
    quiet: dict[str, Any] = {"out": io.StringIO(), "err": io.StringIO()}
    assert main(["compile", str(mission), "-o", str(out), "--until", "verify", "-q"], **quiet) == 0
    plain_out, geo_out = io.StringIO(), io.StringIO()
    assert main(["export-plan", str(out), "--format", "geojson"], plain_out, io.StringIO()) == 0
    reference = Georeference(48.137, 11.575, 30.0)
    code = main(
        ["export-plan", str(out), "--format", "geojson", "--georeference", "48.137,11.575,30"],
        geo_out,
        io.StringIO(),
    )
    assert code == 0
    plain, geo = json.loads(plain_out.getvalue()), json.loads(geo_out.getvalue())

    def pairs(value: Any) -> list[list[float]]:
        if isinstance(value[0], float | int):
            return [value]
        return [p for v in value for p in pairs(v)]

    for a, b in zip(plain["features"], geo["features"], strict=True):
        local, world = pairs(a["geometry"]["coordinates"]), pairs(b["geometry"]["coordinates"])
        assert all(-180 <= lon <= 180 and -90 <= lat <= 90 for lon, lat in world)
        # every map point is written, in order; the points added between two of them (so a
        # long edge stays straight in longitude and latitude) lie on the map's edge
        back = [_map_point(reference, lon, lat) for lon, lat in world]
        found = 0
        for point in back:
            if found < len(local) and math.dist(point, local[found]) < 1e-6:
                found += 1
            else:
                assert 0 < found < len(local)
                edge = LineString([local[found - 1], local[found]])
                assert edge.distance(Point(point)) < 1e-6
        assert found == len(local)


def test_georeference_is_for_geojson_only(tmp_path: Path) -> None:
    err = io.StringIO()
    code = main(
        ["export-plan", str(tmp_path), "--format", "waypoints-csv", "--georeference", "1,2"],
        io.StringIO(),
        err,
    )
    assert code == 2
    assert err.getvalue().startswith("--georeference: error[M086]: ")


@pytest.mark.parametrize("text", ["95,0", "1", "a,b", "1,2,3,4", "nan,1"])
def test_a_bad_georeference_is_a_usage_error(tmp_path: Path, text: str) -> None:
    err = io.StringIO()
    code = main(["export-plan", str(tmp_path), "--georeference", text], io.StringIO(), err)
    assert code == 2
    assert "Traceback" not in err.getvalue()
