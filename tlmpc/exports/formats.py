"""Writers of an exported plan: waypoints (YAML, CSV), GeoJSON, nav_msgs/Path in MCAP."""

from __future__ import annotations

import io
import json
import math
from pathlib import Path
from typing import Any

import yaml

from tlmpc.base.extras import require
from tlmpc.exports.georeference import Georeference, Subdivision, encircles_pole
from tlmpc.exports.plan import Plan, Waypoint
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


def _polygons(geometry: Any) -> list[Any]:
    """The polygons of positive area of a shapely geometry (of any type)."""
    from shapely.geometry import Polygon

    parts = getattr(geometry, "geoms", [geometry])
    return [part for part in parts if isinstance(part, Polygon) and part.area > 0]


def _free_space(plan: Plan) -> list[Any]:
    """The workspace's free space as valid polygons (shapely), one per connected piece.

    A mission's holes may touch the boundary and each other, along an edge too, but rings
    that share an edge do not make a valid polygon (OGC Simple Features, whose geometries
    GeoJSON's are): the holes are subtracted from the outer rings and the rings of the result
    are written, a piece cut off by holes becoming a polygon of its own."""
    import shapely
    from shapely.geometry import Polygon

    pieces = [
        shapely.make_valid(Polygon(outer)).difference(
            shapely.union_all([shapely.make_valid(Polygon(hole)) for hole in holes])
        )
        for outer, holes in ((plan.boundary, plan.holes), *plan.components)
    ]
    return _polygons(shapely.union_all(pieces))


def _polygon_coordinates(polygon: Any) -> list[list[list[float]]]:
    """GeoJSON rings of a shapely polygon, closed, with RFC 7946's right-hand rule (§3.1.6:
    the outer ring counter-clockwise, holes clockwise)."""
    from shapely.geometry.polygon import orient

    oriented = orient(polygon, sign=1.0)
    return [[[x, y] for x, y in ring.coords] for ring in (oriented.exterior, *oriented.interiors)]


def _polygonal_geometry(polygons: list[Any]) -> dict[str, Any]:
    """A Polygon, or a MultiPolygon of several (or no) pieces."""
    if len(polygons) == 1:
        return {"type": "Polygon", "coordinates": _polygon_coordinates(polygons[0])}
    return {"type": "MultiPolygon", "coordinates": [_polygon_coordinates(p) for p in polygons]}


def geojson(
    plan: Plan,
    points: list[Waypoint],
    loop: int | None,
    georeference: Georeference | None = None,
) -> str:
    """A FeatureCollection: workspace, regions, trajectory, waypoints.

    Coordinates are the map frame's metres, or with ``georeference`` WGS 84 longitude and
    latitude (RFC 7946 proper, geometries crossing the antimeridian cut there).  Rings follow
    RFC 7946's right-hand rule (outer counter-clockwise, holes clockwise), in the coordinates
    written.  The workspace is its free space as valid polygons (see :func:`_free_space`).
    """
    from shapely.geometry import Polygon

    features: list[dict[str, Any]] = [
        {
            "type": "Feature",
            "properties": {"kind": "workspace", "name": plan.name},
            "geometry": _polygonal_geometry(_free_space(plan)),
        }
    ]
    for name, ring in plan.regions.items():
        features.append(
            {
                "type": "Feature",
                "properties": {"kind": "region", "name": name},
                "geometry": _polygonal_geometry([Polygon(ring)]),
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
    if georeference is not None:
        subdivision = Subdivision(georeference)
        for feature in features:
            _georeferenced(feature, subdivision)
    collection: dict[str, Any] = {"type": "FeatureCollection", "features": features}
    # strict JSON: a non-finite number (only an edited output has one) is refused, not
    # written as the NaN no GeoJSON reader accepts
    return json.dumps(collection, indent=1, allow_nan=False) + "\n"


def _sheet(longitude: float) -> int:
    """Which copy of the globe an unwrapped longitude lies on: 0 for [-180, 180), 1 for
    [180, 540), -1 for [-540, -180), ..."""
    return math.floor((longitude + 180.0) / 360.0)


def _georeferenced(feature: dict[str, Any], subdivision: Subdivision) -> None:
    """The feature's geometry in ``[longitude, latitude]``, cut at the antimeridian.

    Each point is mapped by :func:`~tlmpc.exports.georeference.to_lon_lat`, and points are
    added along every edge of a polygon or the trajectory so that the straight lon/lat
    segments written lie within :data:`~tlmpc.exports.georeference.EDGE_TOLERANCE` of the
    map's own straight edges
    (:class:`~tlmpc.exports.georeference.Subdivision`); an added point of the trajectory
    gets the time interpolated along its step.  Longitudes are unwrapped to within 180
    degrees of the map origin's, so a geometry stays connected where the map crosses the
    antimeridian; there RFC 7946 §3.1.9 asks for it to be cut in parts none of which crosses
    it.  Polygons are cut along ±180 (a MultiPolygon), a trajectory becomes a
    MultiLineString whose parts end and start on the antimeridian (its ``times`` then one
    list per part, the crossing's time interpolated), and every longitude written is in
    [-180, 180].  Rings are oriented again in longitude and latitude.  A ring around a pole,
    which no GeoJSON polygon holds, is M088."""
    geometry = feature["geometry"]
    kind, coordinates = geometry["type"], geometry["coordinates"]

    def wrapped(longitude: float, latitude: float) -> list[float]:
        return [longitude - 360.0 * _sheet(longitude), latitude]

    if kind == "Point":
        geometry["coordinates"] = wrapped(*subdivision.lon_lat(*coordinates))
    elif kind == "MultiPoint":
        geometry["coordinates"] = [wrapped(*subdivision.lon_lat(*p)) for p in coordinates]
    elif kind == "LineString":
        import numpy as np

        points, at = subdivision.path(coordinates)
        given = feature["properties"].get("times")
        times = None if given is None else np.interp(at, range(len(given)), given).tolist()
        parts, part_times = _cut_line(points, times)
        if len(parts) > 1:
            geometry["type"], geometry["coordinates"] = "MultiLineString", parts
        else:
            geometry["coordinates"] = parts[0]
        if part_times is not None:
            feature["properties"]["times"] = part_times if len(parts) > 1 else part_times[0]
    else:
        from shapely.geometry import Polygon

        polygons = [coordinates] if kind == "Polygon" else coordinates
        lon_lat = []
        for rings in polygons:
            mapped = [subdivision.path(ring)[0] for ring in rings]
            if any(encircles_pole(ring) for ring in mapped):
                raise _around_a_pole(feature)
            lon_lat.append(Polygon(mapped[0], mapped[1:]))
        feature["geometry"] = _polygonal_geometry(
            [piece for polygon in lon_lat for piece in _cut_polygon(polygon)]
        )


def _around_a_pole(feature: dict[str, Any]) -> Exception:
    from tlmpc.base.errors import UsageError, error

    properties = feature["properties"]
    what = properties["kind"]
    if what == "region":
        what = f"region {properties['name']!r}"
    return UsageError(
        error(
            "M088",
            f"with this --georeference the {what} goes around a pole, which no GeoJSON "
            "polygon can hold",
            hint="export without --georeference (map metres), or place the map's origin "
            "where the map does not reach a pole",
            file="--georeference",
        )
    )


def _cut_polygon(polygon: Any) -> list[Any]:
    """The polygon (unwrapped longitudes) cut into pieces within [-180, 180] each, moved there
    by whole turns; a polygon that does not cross the antimeridian is kept as it is."""
    from shapely import affinity
    from shapely.geometry import box

    west, _, east, _ = polygon.bounds
    if _sheet(west) == _sheet(east):
        return [affinity.translate(polygon, -360.0 * _sheet(west)) if _sheet(west) else polygon]
    pieces: list[Any] = []
    for sheet in range(_sheet(west), _sheet(east) + 1):
        low = -180.0 + 360.0 * sheet
        window = box(low, -90.0, low + 360.0, 90.0)
        pieces += [
            affinity.translate(piece, -360.0 * sheet)
            for piece in _polygons(polygon.intersection(window))
        ]
    return pieces


def _cut_line(
    points: list[tuple[float, float]], times: list[float] | None
) -> tuple[list[list[list[float]]], list[list[float]] | None]:
    """A polyline (unwrapped longitudes) cut where it crosses the antimeridian: its parts, in
    [-180, 180] each, and the times of their points (``None`` without ``times``).

    A map is far smaller than the Earth, so one step crosses at most one antimeridian."""
    parts: list[list[list[float]]] = [[]]
    part_times: list[list[float]] = [[]]
    for index, (longitude, latitude) in enumerate(points):
        sheet = _sheet(longitude)
        if index > 0:
            previous_longitude, previous_latitude = points[index - 1]
            previous_sheet = _sheet(previous_longitude)
            if sheet != previous_sheet:
                boundary = -180.0 + 360.0 * max(sheet, previous_sheet)
                share = (boundary - previous_longitude) / (longitude - previous_longitude)
                crossing = previous_latitude + share * (latitude - previous_latitude)
                parts[-1].append([boundary - 360.0 * previous_sheet, crossing])
                parts.append([[boundary - 360.0 * sheet, crossing]])
                if times is not None:
                    at = times[index - 1] + share * (times[index] - times[index - 1])
                    part_times[-1].append(at)
                    part_times.append([at])
        parts[-1].append([longitude - 360.0 * sheet, latitude])
        if times is not None:
            part_times[-1].append(times[index])
    return parts, part_times if times is not None else None


PATH_TYPE = "nav_msgs/msg/Path"

#: A ROS 2 ``builtin_interfaces/msg/Time`` holds whole seconds in a signed 32-bit field
#: (``int32 sec``): stamps reach 2^31 - 1 s and 999,999,999 ns.
MAX_STAMP_SECONDS = 2**31


def _fits_a_stamp(seconds: float) -> bool:
    """Whether a ROS 2 stamp holds the time ``seconds`` (as it is written: whole
    nanoseconds); a time too large for nanoseconds to be counted (1e300) does not."""
    if not 0.0 <= seconds < MAX_STAMP_SECONDS:
        return False
    return _stamp_nanoseconds(seconds) < MAX_STAMP_SECONDS * 1_000_000_000


def _stamp_nanoseconds(seconds: float) -> int:
    """The time as the whole nanoseconds a stamp holds (rounded, as the stamp is written)."""
    return round(seconds * 1e9)


def path_mcap(
    plan: Plan,
    points: list[Waypoint],
    topic: str = "/plan",
    frame_id: str = "map",
    *,
    source: Path | None = None,
) -> bytes:
    """An MCAP file with one ``nav_msgs/msg/Path`` (CDR, ROS 2 schema) on ``topic``.

    Pose stamps are the plan's times; the message's log time is the first of them.  A time
    no stamp holds is M085, at ``source`` (the trajectory read) when given.
    """
    require("mcap.writer", "writing a nav_msgs/Path MCAP file")
    require("rosbags.typesys", "writing a nav_msgs/Path MCAP file")
    from mcap.writer import Writer
    from rosbags.typesys import Stores, get_typestore

    from tlmpc.base.errors import UsageError, error

    # the stamp as written is compared (rounded to whole nanoseconds)
    late = [w.t for w in points if not _fits_a_stamp(w.t)]
    if late:
        raise UsageError(
            error(
                "M085",
                f"a plan time ({late[0]:g} s) does not fit a ROS 2 time stamp "
                f"(0 to {MAX_STAMP_SECONDS - 1:,} s and 999,999,999 ns)",
                hint="export this plan as waypoints-yaml, waypoints-csv or geojson",
                file=None if source is None else str(source),
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
        nanoseconds = _stamp_nanoseconds(seconds)
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
    log_time = _stamp_nanoseconds(first)
    writer.add_message(channel, log_time=log_time, data=data, publish_time=log_time, sequence=0)
    writer.finish()  # type: ignore[no-untyped-call]
    return buffer.getvalue()
