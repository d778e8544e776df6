"""`tlmpc export-plan`: valid GeoJSON (shapely as the oracle), the antimeridian (RFC 7946
§3.1.9), a southern `--georeference`, and the ROS 2 stamp range of `path-mcap`."""

from __future__ import annotations

import io
import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
import shapely.affinity
from shapely.geometry import Polygon, box, shape

from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.exports.formats import path_mcap
from tlmpc.exports.georeference import Georeference, to_lon_lat
from tlmpc.exports.plan import Plan, Waypoint

ROOT = Path(__file__).resolve().parents[2]


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def compiled(tmp_path: Path, text: str) -> Path:
    mission = tmp_path / "mission.yaml"
    mission.write_text(text)
    out = tmp_path / "out"
    code, _, err = run("compile", str(mission), "-o", str(out), "--until", "verify", "-q")
    assert code == 0, err
    return out


def features(document: dict[str, Any], kind: str) -> list[dict[str, Any]]:
    return [f for f in document["features"] if f["properties"]["kind"] == kind]


def polygons(geometry: dict[str, Any]) -> list[list[list[list[float]]]]:
    if geometry["type"] == "Polygon":
        return [geometry["coordinates"]]
    assert geometry["type"] == "MultiPolygon"
    return list(geometry["coordinates"])


def right_handed(geometry: dict[str, Any]) -> bool:
    """RFC 7946 §3.1.6: exterior rings counter-clockwise, holes clockwise."""
    return all(
        Polygon(rings[0]).exterior.is_ccw and not any(Polygon(r).exterior.is_ccw for r in rings[1:])
        for rings in polygons(geometry)
    )


TOUCHING_HOLES = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 10]}
  holes:
    - {rect: [0, 4, 2, 6]}
    - {rect: [5, 5, 7, 10]}
    - {rect: [3, 1, 4, 2]}
    - {rect: [4, 1, 5, 2]}
    - {rect: [8, 0, 10, 2]}
regions:
  goal: {rect: [8, 8, 9, 9]}
robot: {start: [1, 1]}
ltl: "F goal"
"""


def test_workspace_with_holes_on_the_wall_and_on_each_other_is_valid(tmp_path: Path) -> None:
    out = compiled(tmp_path, TOUCHING_HOLES)
    code, text, err = run("export-plan", str(out), "--format", "geojson")
    assert code == 0, err
    (workspace,) = features(json.loads(text), "workspace")
    geometry = shape(workspace["geometry"])
    assert geometry.is_valid, shapely.is_valid_reason(geometry)
    holes = [box(0, 4, 2, 6), box(5, 5, 7, 10), box(3, 1, 4, 2), box(4, 1, 5, 2), box(8, 0, 10, 2)]
    assert geometry.equals(box(0, 0, 10, 10).difference(shapely.union_all(holes)))
    assert right_handed(workspace["geometry"])


SPLIT = TOUCHING_HOLES.replace("{rect: [5, 5, 7, 10]}", "{rect: [5, 0, 6, 10]}").replace(
    "    - {rect: [8, 0, 10, 2]}\n", ""
)


def test_holes_that_cut_the_workspace_give_a_multipolygon(tmp_path: Path) -> None:
    mission = tmp_path / "mission.yaml"
    mission.write_text(SPLIT.replace("goal: {rect: [8, 8, 9, 9]}", "goal: {rect: [2, 8, 3, 9]}"))
    out = tmp_path / "out"
    code, _, err = run("compile", str(mission), "-o", str(out), "-q")
    if code != 0:  # a workspace in two pieces may be refused as such: nothing to export
        pytest.skip(err)
    code, text, err = run("export-plan", str(out), "--format", "geojson")
    assert code == 0, err
    (workspace,) = features(json.loads(text), "workspace")
    geometry = shape(workspace["geometry"])
    assert geometry.is_valid
    assert workspace["geometry"]["type"] == "MultiPolygon"
    assert right_handed(workspace["geometry"])


PATROL = (ROOT / "specs" / "patrol.yaml").read_text()


@pytest.fixture(scope="module")
def patrol(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("patrol")
    return compiled(folder, PATROL)


def unwrapped(reference: Georeference, x: float, y: float) -> tuple[float, float]:
    longitude, latitude = to_lon_lat(reference, x, y)
    return reference.longitude + math.remainder(longitude - reference.longitude, 360), latitude


@pytest.mark.parametrize(
    "reference",
    [
        Georeference(0.0, 179.9999, 0.0),  # the trajectory crosses six times
        Georeference(-41.3, 180.0, 75.0),
        Georeference(64.0, -179.99995, 160.0),
        Georeference(10.0, -179.99995, 200.0),
    ],
)
def test_geometries_across_the_antimeridian_are_cut_there(
    patrol: Path, reference: Georeference
) -> None:
    text = f"{reference.latitude},{reference.longitude},{reference.yaw}"
    code, plain, err = run("export-plan", str(patrol), "--format", "geojson")
    assert code == 0, err
    code, geo, err = run(
        "export-plan", str(patrol), "--format", "geojson", f"--georeference={text}"
    )
    assert code == 0, err
    local, world = json.loads(plain), json.loads(geo)
    crossed = 0
    for near, far in zip(local["features"], world["features"], strict=True):
        geometry = far["geometry"]
        if geometry["type"] not in ("Polygon", "MultiPolygon"):
            continue
        pieces = [Polygon(rings[0], rings[1:]) for rings in polygons(geometry)]
        for piece in pieces:
            west, _, east, _ = piece.bounds
            assert -180 <= west <= east <= 180
            assert east - west < 1  # a few metres: never a band around the globe
            assert piece.is_valid
        assert right_handed(geometry)
        # the oracle: the map-frame geometry mapped point by point, longitudes unwrapped,
        # covers the same ground as the pieces put side by side again
        mapped = [
            Polygon(
                [unwrapped(reference, *p) for p in rings[0]],
                [[unwrapped(reference, *p) for p in r] for r in rings[1:]],
            )
            for rings in polygons(near["geometry"])
        ]
        whole = shapely.union_all(mapped)
        shifted = [
            shapely.affinity.translate(
                piece, 360.0 * round((reference.longitude - piece.centroid.x) / 360.0)
            )
            for piece in pieces
        ]
        assert shapely.union_all(shifted).symmetric_difference(whole).area < 1e-9 * whole.area
        crossed += len(pieces) > len(mapped)
    assert crossed  # the map does cross the antimeridian
    (near_line,) = features(local, "trajectory")
    (far_line,) = features(world, "trajectory")
    parts, times = far_line["geometry"]["coordinates"], far_line["properties"]["times"]
    if far_line["geometry"]["type"] == "LineString":  # this trajectory stays on one side
        parts, times = [parts], [times]
    else:
        assert far_line["geometry"]["type"] == "MultiLineString"
    assert [len(p) for p in parts] == [len(t) for t in times]
    for part in parts:  # each part on one side: its inner points' side, its ends' too
        assert len({math.copysign(1.0, lon) for lon, _ in part}) == 1
    for (before, after), (times_before, times_after) in zip(
        itertools.pairwise(parts), itertools.pairwise(times), strict=True
    ):
        assert abs(before[-1][0]) == 180.0  # cut on the antimeridian, from one side to the other
        assert after[0][0] == -before[-1][0]
        assert before[-1][1] == after[0][1]
        # the crossing's time: interpolated as the longitude, unwrapped, crosses 180
        (lon0, _), (lon1, _) = before[-2], after[1]
        east0, east1 = (180.0 + math.remainder(lon - 180.0, 360.0) for lon in (lon0, lon1))
        share = (180.0 - east0) / (east1 - east0)
        t0, t1 = times_before[-2], times_after[1]
        assert math.isclose(times_before[-1], t0 + share * (t1 - t0), rel_tol=1e-9)
        assert times_after[0] == times_before[-1]
    # the samples are all there, in order, between the crossing points
    inner = [p for part in parts for p in part[1:-1]]
    inner = [parts[0][0], *inner, parts[-1][-1]]
    samples = near_line["geometry"]["coordinates"]
    assert len(inner) == len(samples)
    for (lon, lat), (x, y) in zip(inner, samples, strict=True):
        want_lon, want_lat = to_lon_lat(reference, x, y)
        assert math.isclose(lat, want_lat, abs_tol=1e-12)
        assert abs(math.remainder(lon - want_lon, 360.0)) < 1e-9
    flat_times = [t for part in times for t in part[1:-1]]
    flat_times = [times[0][0], *flat_times, times[-1][-1]]
    assert flat_times == near_line["properties"]["times"]
    for lon, _ in features(world, "waypoints")[0]["geometry"]["coordinates"]:
        assert -180 <= lon <= 180


def test_a_southern_georeference_follows_the_flag(patrol: Path) -> None:
    code, separate, err = run(
        "export-plan", str(patrol), "--format", "geojson", "--georeference", "-33.86,151.21"
    )
    assert code == 0, err
    code, joined, _ = run(
        "export-plan", str(patrol), "--format", "geojson", "--georeference=-33.86,151.21"
    )
    assert separate == joined
    (waypoints,) = features(json.loads(separate), "waypoints")
    lon, lat = waypoints["geometry"]["coordinates"][0]
    assert math.isclose(lat, -33.86, abs_tol=0.01)
    assert math.isclose(lon, 151.21, abs_tol=0.01)


def _plan_until(t: float) -> tuple[Plan, list[Waypoint]]:
    samples = np.array([[0.0, 0.0, 0.0], [t, 1.0, 0.0]])
    plan = Plan(
        samples=samples,
        loop_start=None,
        name="p",
        boundary=((0.0, 0.0), (2.0, 0.0), (2.0, 2.0)),
        holes=(),
        regions={},
        formula="",
    )
    return plan, [Waypoint(t=0.0, x=0.0, y=0.0, yaw=0.0), Waypoint(t=t, x=1.0, y=0.0, yaw=0.0)]


@pytest.mark.parametrize("t", [2.0**31, 3.0e9, 2.0**32 - 1, -1e-3])
def test_a_time_beyond_a_ros2_stamp_is_m085(t: float) -> None:
    """builtin_interfaces/msg/Time's ``sec`` is int32: 2^31 s does not fit, nor does a
    negative time."""
    pytest.importorskip("mcap")
    pytest.importorskip("rosbags")
    with pytest.raises(UsageError) as raised:
        path_mcap(*_plan_until(t))
    assert raised.value.diagnostics[0].code == "M085"


def test_the_last_second_a_ros2_stamp_holds_is_written() -> None:
    pytest.importorskip("mcap")
    rosbags = pytest.importorskip("rosbags.typesys")
    from mcap.reader import make_reader

    t = 2.0**31 - 1 + 0.5
    data = path_mcap(*_plan_until(t))
    store = rosbags.get_typestore(rosbags.Stores.ROS2_HUMBLE)
    ((_, _, message),) = list(make_reader(io.BytesIO(data)).iter_messages())
    path = store.deserialize_cdr(message.data, "nav_msgs/msg/Path")
    stamp = path.poses[-1].header.stamp
    assert (stamp.sec, stamp.nanosec) == (2**31 - 1, 500_000_000)


def test_flag_and_stamp_refusals_are_located(tmp_path: Path) -> None:
    """M084 at the flag as given, M085 at the trajectory whose time no stamp holds."""
    pytest.importorskip("mcap")
    pytest.importorskip("rosbags")
    slow = (
        "version: 1\nworkspace: {boundary: {rect: [0, 0, 10, 10]}}\n"
        "regions: {a: {rect: [8, 8, 9, 9]}}\nrobot: {start: [1, 1], max_speed: 4.0e-9}\n"
        "task: [visit a]\n"
    )
    out = compiled(tmp_path, slow)
    target = str(tmp_path / "p.mcap")
    code, _, err = run("export-plan", str(out), "--format", "path-mcap", "-o", target)
    assert code == 2, err
    assert err.startswith(f"{out / 'trace.json'}: error[M085]: "), err
    code, _, err = run(
        "export-plan", str(out), "--format", "path-mcap", "-o", target, "--frame-id", ""
    )
    assert code == 2, err
    assert err.startswith("--frame-id '': error[M084]: "), err
