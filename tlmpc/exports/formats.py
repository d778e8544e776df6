"""Writers of an exported plan: waypoints (YAML, CSV), GeoJSON, nav_msgs/Path in MCAP."""

from __future__ import annotations

import io
import json
import math
from typing import Any

import yaml

from tlmpc.base.extras import require
from tlmpc.exports.georeference import Georeference, to_lon_lat
from tlmpc.exports.plan import Plan, Ring, Waypoint
from tlmpc.io.outputs import csv_cell, yaml_float


def _quaternion(yaw: float) -> dict[str, float]:
    return {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2.0), "w": math.cos(yaw / 2.0)}


def waypoints_yaml(
    plan: Plan, points: list[Waypoint], loop: int | None, frame_id: str = "map"
) -> str:
    """``tlmpc.waypoints/1``: frame, loop start and poses (yaw and quaternion) with plan times.

    The text is what ``yaml.safe_dump(document, sort_keys=False, default_flow_style=None)``
    writes, but the waypoints (numbers only) are written here line by line: PyYAML's emitter
    takes half a minute and 2 GB for a trace of a few hundred thousand samples.  The names
    (the mission's, the frame's) are still quoted and escaped by PyYAML."""
    header: dict[str, Any] = {
        "format": "tlmpc.waypoints/1",
        "mission": plan.name,
        "task": plan.formula,
        "frame_id": frame_id,
        "loop_start": loop,
    }
    if not points:
        return yaml.safe_dump({**header, "waypoints": []}, sort_keys=False, default_flow_style=None)
    out = io.StringIO()
    # block style, as the top level is when it holds the waypoints' list
    out.write(yaml.safe_dump(header, sort_keys=False, default_flow_style=False))
    out.write("waypoints:\n")
    for w in points:
        q = _quaternion(w.yaw)
        out.write(
            f"- t: {yaml_float(w.t)}\n  x: {yaml_float(w.x)}\n  y: {yaml_float(w.y)}\n"
            f"  yaw: {yaml_float(w.yaw)}\n  orientation: {{x: {yaml_float(q['x'])}, "
            f"y: {yaml_float(q['y'])}, z: {yaml_float(q['z'])}, w: {yaml_float(q['w'])}}}\n"
        )
    return out.getvalue()


def waypoints_csv(plan: Plan, points: list[Waypoint], loop: int | None) -> str:
    """``t,x,y,yaw`` rows; comment lines give the mission and the loop start (row index).

    The mission's name is the second cell of the first comment line, one neutralised CSV cell
    (a name's separators, quotes or newlines inside the text of the first cell would start new
    cells there, where quoting does not work): it adds neither a row nor a formula."""
    out = io.StringIO()
    out.write(f"# tlmpc.waypoints/1 mission,{csv_cell(plan.name)}\n")
    out.write(f"# loop_start: {'none' if loop is None else loop}\n")
    out.write("t,x,y,yaw\n")
    for w in points:
        out.write(f"{w.t!r},{w.x!r},{w.y!r},{w.yaw!r}\n")
    return out.getvalue()


def _closed(ring: Ring) -> list[list[float]]:
    coords = [[x, y] for x, y in ring]
    return [*coords, coords[0]]


def _oriented(ring: Ring, ccw: bool) -> Ring:
    area = sum(
        x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(ring, ring[1:] + ring[:1], strict=True)
    )
    return ring if (area > 0) == ccw else tuple(reversed(ring))


def _rings(boundary: Ring, holes: tuple[Ring, ...]) -> list[list[list[float]]]:
    return [_closed(_oriented(boundary, True))] + [_closed(_oriented(h, False)) for h in holes]


def _workspace_geometry(plan: Plan) -> dict[str, Any]:
    """A Polygon, or a MultiPolygon when the workspace has further components."""
    if not plan.components:
        return {"type": "Polygon", "coordinates": _rings(plan.boundary, plan.holes)}
    return {
        "type": "MultiPolygon",
        "coordinates": [_rings(plan.boundary, plan.holes)]
        + [_rings(outer, inner) for outer, inner in plan.components],
    }


def geojson(
    plan: Plan,
    points: list[Waypoint],
    loop: int | None,
    georeference: Georeference | None = None,
) -> str:
    """A FeatureCollection: workspace, regions, trajectory, waypoints.

    Coordinates are the map frame's metres, or with ``georeference`` WGS 84 longitude and
    latitude (RFC 7946 proper).  Rings follow RFC 7946's right-hand rule (outer
    counter-clockwise, holes clockwise; a yaw or a mirror-free georeference keeps the turn).
    """
    features: list[dict[str, Any]] = [
        {
            "type": "Feature",
            "properties": {"kind": "workspace", "name": plan.name},
            "geometry": _workspace_geometry(plan),
        }
    ]
    for name, ring in plan.regions.items():
        features.append(
            {
                "type": "Feature",
                "properties": {"kind": "region", "name": name},
                "geometry": {"type": "Polygon", "coordinates": [_closed(_oriented(ring, True))]},
            }
        )
    samples = plan.samples
    features.append(
        {
            "type": "Feature",
            "properties": {
                "kind": "trajectory",
                "task": plan.formula,
                "loop_start": plan.loop_start,
                "times": samples[:, 0].tolist(),
            },
            "geometry": {
                "type": "LineString" if len(samples) > 1 else "Point",
                "coordinates": samples[:, 1:].tolist()
                if len(samples) > 1
                else samples[0, 1:].tolist(),
            },
        }
    )
    features.append(
        {
            "type": "Feature",
            "properties": {
                "kind": "waypoints",
                "loop_start": loop,
                "yaw": [w.yaw for w in points],
                "times": [w.t for w in points],
            },
            "geometry": {"type": "MultiPoint", "coordinates": [[w.x, w.y] for w in points]},
        }
    )
    collection: dict[str, Any] = {"type": "FeatureCollection", "features": features}
    if georeference is not None:
        _georeferenced(collection, georeference)
    # strict JSON: a non-finite number (only an edited output has one) is refused, not
    # written as the NaN no GeoJSON reader accepts
    return json.dumps(collection, indent=1, allow_nan=False) + "\n"


def _georeferenced(collection: dict[str, Any], reference: Georeference) -> None:
    """Every coordinate pair of ``collection`` mapped to ``[longitude, latitude]``."""

    def convert(value: Any) -> Any:
        if (
            isinstance(value, list)
            and len(value) == 2
            and all(isinstance(v, float | int) for v in value)
        ):
            return list(to_lon_lat(reference, float(value[0]), float(value[1])))
        if isinstance(value, list):
            return [convert(v) for v in value]
        return value

    for feature in collection["features"]:
        geometry = feature["geometry"]
        geometry["coordinates"] = convert(geometry["coordinates"])


PATH_TYPE = "nav_msgs/msg/Path"

#: A ROS ``builtin_interfaces/Time`` holds whole seconds in an unsigned 32-bit field.
MAX_STAMP_SECONDS = 2**32


def path_mcap(
    plan: Plan, points: list[Waypoint], topic: str = "/plan", frame_id: str = "map"
) -> bytes:
    """An MCAP file with one ``nav_msgs/msg/Path`` (CDR, ROS 2 schema) on ``topic``.

    Pose stamps are the plan's times; the message's log time is the first of them.
    """
    require("mcap.writer", "writing a nav_msgs/Path MCAP file")
    require("rosbags.typesys", "writing a nav_msgs/Path MCAP file")
    from mcap.writer import Writer
    from rosbags.typesys import Stores, get_typestore

    from tlmpc.base.errors import UsageError, error

    late = [w.t for w in points if not 0.0 <= w.t < MAX_STAMP_SECONDS]
    if late:
        raise UsageError(
            error(
                "M085",
                f"a plan time ({late[0]:g} s) does not fit a ROS time stamp "
                f"(0 to {MAX_STAMP_SECONDS:,} s)",
                hint="export this plan as waypoints-yaml, waypoints-csv or geojson",
            )
        )

    store = get_typestore(Stores.ROS2_HUMBLE)
    types: Any = store.types
    time_type, header_type = types["builtin_interfaces/msg/Time"], types["std_msgs/msg/Header"]
    pose_stamped, pose_type = (
        types["geometry_msgs/msg/PoseStamped"],
        types["geometry_msgs/msg/Pose"],
    )
    point_type, quat_type = types["geometry_msgs/msg/Point"], types["geometry_msgs/msg/Quaternion"]

    def stamp(seconds: float) -> Any:
        nanoseconds = max(0, round(seconds * 1e9))
        return time_type(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)

    poses = [
        pose_stamped(
            header=header_type(stamp=stamp(w.t), frame_id=frame_id),
            pose=pose_type(
                position=point_type(x=w.x, y=w.y, z=0.0),
                orientation=quat_type(**_quaternion(w.yaw)),
            ),
        )
        for w in points
    ]
    first = points[0].t if points else 0.0
    message = types[PATH_TYPE](
        header=header_type(stamp=stamp(first), frame_id=frame_id), poses=poses
    )
    data = bytes(store.serialize_cdr(message, PATH_TYPE))
    definition, _ = store.generate_msgdef(PATH_TYPE, ros_version=2)
    buffer = io.BytesIO()
    writer = Writer(buffer)
    writer.start(profile="ros2", library="tlmpc")
    schema = writer.register_schema(
        name=PATH_TYPE, encoding="ros2msg", data=definition.encode("utf-8")
    )
    channel = writer.register_channel(topic=topic, message_encoding="cdr", schema_id=schema)
    log_time = max(0, round(first * 1e9))
    writer.add_message(channel, log_time=log_time, data=data, publish_time=log_time, sequence=0)
    writer.finish()  # type: ignore[no-untyped-call]
    return buffer.getvalue()
