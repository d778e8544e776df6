"""Plans out: waypoints (YAML, CSV), nav_msgs/Path in MCAP and GeoJSON agree with the plan."""

from __future__ import annotations

import io
import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import Polygon, shape

from tlmpc.cli import main
from tlmpc.exports.plan import Plan, read_plan, waypoints
from tlmpc.importers.logs import read_log

MISSION = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 6, 4]}
  holes: [{rect: [2.5, 1, 3.5, 3]}]
regions:
  a: {rect: [0.5, 0.5, 1.5, 1.5]}
  b: {rect: [4.5, 2.5, 5.5, 3.5]}
robot: {start: [1, 3]}
task: ["patrol a, b"]
"""


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("plan")
    mission = directory / "patrol.yaml"
    mission.write_text(MISSION)
    code, _, err = run("compile", str(mission), "-o", str(directory / "out"), "--until", "verify")
    assert code == 0, err
    return directory / "out"


def test_waypoints_yaml_keeps_the_loop(compiled: Path) -> None:
    code, out, err = run("export-plan", str(compiled), "--spacing", "0.5")
    assert code == 0, err
    document = yaml.safe_load(out)
    plan = read_plan(compiled)
    assert plan.loop_start is not None
    points = document["waypoints"]
    loop = document["loop_start"]
    assert points[loop]["t"] == plan.samples[plan.loop_start, 0]
    assert (points[0]["x"], points[0]["y"]) == tuple(plan.samples[0, 1:])
    assert (points[-1]["x"], points[-1]["y"]) == tuple(plan.samples[-1, 1:])
    for point in points:
        quaternion = point["orientation"]
        assert math.isclose(2 * math.atan2(quaternion["z"], quaternion["w"]), point["yaw"])


def test_waypoints_csv_is_a_log_the_verifier_reads(compiled: Path, tmp_path: Path) -> None:
    csv = tmp_path / "plan.csv"
    code, _, err = run("export-plan", str(compiled), "--format", "waypoints-csv", "-o", str(csv))
    assert code == 0, err
    plan = read_plan(compiled)
    assert np.array_equal(read_log(csv).samples, plan.samples)  # spacing 0: every sample


def test_path_mcap_reads_back_with_rosbags(compiled: Path, tmp_path: Path) -> None:
    from rosbags.highlevel import AnyReader

    out = tmp_path / "plan.mcap"
    code, _, err = run(
        "export-plan", str(compiled), "--format", "path-mcap", "-o", str(out), "--spacing", "0.3"
    )
    assert code == 0, err
    plan = read_plan(compiled)
    expected, _ = waypoints(plan, 0.3)
    with AnyReader([out]) as reader:
        (connection,) = reader.connections
        assert connection.topic == "/plan"
        assert connection.msgtype == "nav_msgs/msg/Path"
        ((conn, _, raw),) = list(reader.messages())
        message: Any = reader.deserialize(raw, conn.msgtype)
    assert message.header.frame_id == "map"
    assert len(message.poses) == len(expected)
    for pose, want in zip(message.poses, expected, strict=True):
        assert pose.pose.position.x == want.x
        assert pose.pose.position.y == want.y
        stamp = pose.header.stamp.sec + pose.header.stamp.nanosec * 1e-9
        assert stamp == pytest.approx(want.t, abs=1e-9)
        yaw = 2 * math.atan2(pose.pose.orientation.z, pose.pose.orientation.w)
        assert math.isclose(math.remainder(yaw - want.yaw, 2 * math.pi), 0.0, abs_tol=1e-12)


def test_geojson_has_the_map_regions_and_trajectory(compiled: Path) -> None:
    code, out, err = run("export-plan", str(compiled), "--format", "geojson")
    assert code == 0, err
    document = json.loads(out)
    kinds: dict[str, list[Any]] = {}
    for feature in document["features"]:
        kinds.setdefault(feature["properties"]["kind"], []).append(feature)
    (workspace,) = kinds["workspace"]
    geometry = shape(workspace["geometry"])
    assert geometry.equals(
        Polygon([(0, 0), (6, 0), (6, 4), (0, 4)]).difference(
            Polygon([(2.5, 1), (3.5, 1), (3.5, 3), (2.5, 3)])
        )
    )
    exterior = workspace["geometry"]["coordinates"][0]
    assert Polygon(exterior).exterior.is_ccw  # RFC 7946: outer rings counter-clockwise
    assert not Polygon(workspace["geometry"]["coordinates"][1]).exterior.is_ccw
    assert {f["properties"]["name"] for f in kinds["region"]} == {"a", "b"}
    (trajectory,) = kinds["trajectory"]
    plan = read_plan(compiled)
    assert trajectory["geometry"]["coordinates"] == plan.samples[:, 1:].tolist()


def _plan(samples: np.ndarray, loop: int | None) -> Plan:
    return Plan(
        samples=samples,
        loop_start=loop,
        name="p",
        boundary=((0.0, 0.0), (1.0, 0.0), (1.0, 1.0)),
        holes=(),
        regions={},
        formula="",
    )


@given(
    steps=st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1)), min_size=1, max_size=40),
    spacing=st.floats(0, 2),
    loop_fraction=st.one_of(st.none(), st.floats(0, 1)),
)
def test_waypoint_thinning_keeps_the_ends_the_loop_and_the_spacing(
    steps: list[tuple[float, float]], spacing: float, loop_fraction: float | None
) -> None:
    xy = np.cumsum(np.array(steps), axis=0)
    samples = np.column_stack([np.arange(len(xy), dtype=float), xy])
    loop = None if loop_fraction is None else int(loop_fraction * (len(xy) - 1))
    points, loop_index = waypoints(_plan(samples, loop), spacing)
    times = [int(p.t) for p in points]
    assert times[0] == 0
    assert times[-1] == len(xy) - 1
    assert times == sorted(set(times))
    if loop is None:
        assert loop_index is None
    else:
        assert loop_index is not None
        assert times[loop_index] == loop
    forced = {0, len(xy) - 1, loop}
    for previous, current in itertools.pairwise(times):
        if current not in forced:
            gap = math.dist(samples[previous, 1:], samples[current, 1:])
            assert gap >= spacing
        # Nothing skipped could have been kept: every skipped sample is closer than spacing.
        for skipped in range(previous + 1, current):
            assert math.dist(samples[previous, 1:], samples[skipped, 1:]) < spacing


def test_a_sample_exactly_the_spacing_away_is_kept() -> None:
    samples = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 1.5, 0.0], [3.0, 2.5, 0.0]])
    points, _ = waypoints(_plan(samples, None), 1.0)
    assert [p.t for p in points] == [0.0, 1.0, 3.0]


def test_bad_export_requests_get_diagnostics(compiled: Path, tmp_path: Path) -> None:
    code, _, err = run("export-plan", str(tmp_path))
    assert code == 2
    assert "error[M080]" in err
    code, _, err = run("export-plan", str(compiled), "--format", "path-mcap")
    assert code == 2
    assert "error[M083]" in err
    code, _, err = run("export-plan", str(compiled), "--spacing", "-1")
    assert code == 2
    assert "--spacing -1: error[M082]" in err
    assert "hint: the least distance between kept waypoints" in err
    code, _, err = run("export-plan", str(compiled), "-o", str(tmp_path / "no" / "x.yaml"))
    assert code == 2
    assert "error[M083]" in err
