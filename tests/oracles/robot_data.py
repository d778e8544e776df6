"""Robot-data test helpers: the shared data folder, map and bag writers, and nav2 oracles.

The shared folder is ``$TLMPC_SHARED_DATA``, else ``<repo>/../shared/data``; tests that need it
skip cleanly when it is absent.  Everything else here writes its own files, so the suite passes
anywhere.
"""

from __future__ import annotations

import os
from collections import deque
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

ROOT = Path(__file__).resolve().parent.parent.parent


def shared_data() -> Path:
    """The shared data folder (which may not exist)."""
    override = os.environ.get("TLMPC_SHARED_DATA")
    return Path(override) if override else ROOT.parent / "shared" / "data"


def require_shared(relative: str) -> Path:
    """``shared_data() / relative``, skipping the test when it is absent."""
    path = shared_data() / relative
    if not path.exists():
        pytest.skip(f"shared data {relative} is absent")
    return path


def nav2_cell(
    pixel: float,
    *,
    mode: str,
    negate: bool,
    occupied: float,
    free: float,
    opaque: bool = True,
) -> int:
    """nav2 map_io's conversion of one pixel shade (0..1), written from its source, scalar."""
    occ = pixel if negate else 1.0 - pixel
    if mode == "raw":
        value = round(pixel * 255.0)
        return int(value) if 0 <= value <= 100 else -1
    if mode == "scale" and not opaque:
        return -1
    if occupied < occ:
        return 100
    if occ < free:
        return 0
    if mode == "trinary":
        return -1
    return int(np.rint((occ - free) / (occupied - free) * 100.0))


def write_map(
    directory: Path,
    name: str,
    image: npt.NDArray[np.uint8],
    *,
    resolution: float = 0.1,
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
    mode: str | None = None,
    negate: int = 0,
    occupied: float = 0.65,
    free: float = 0.196,
    suffix: str = "pgm",
) -> Path:
    """A map_server map: ``name.yaml`` and its image (row 0 is the top of the map)."""
    from PIL import Image

    Image.fromarray(image).save(directory / f"{name}.{suffix}")
    lines = [
        f"image: {name}.{suffix}",
        f"resolution: {resolution!r}",
        f"origin: [{origin[0]!r}, {origin[1]!r}, {origin[2]!r}]",
        f"negate: {negate}",
        f"occupied_thresh: {occupied!r}",
        f"free_thresh: {free!r}",
    ]
    if mode is not None:
        lines.append(f"mode: {mode}")
    path = directory / f"{name}.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path


def image_from_free(free: npt.NDArray[np.bool_]) -> npt.NDArray[np.uint8]:
    """A trinary image (254 free, 0 occupied) of a y-up boolean grid (flipped to image rows)."""
    return np.where(free[::-1], 254, 0).astype(np.uint8)


def components(free: npt.NDArray[np.bool_]) -> list[set[tuple[int, int]]]:
    """4-connected components of true cells, by breadth-first search (the oracle)."""
    seen = np.zeros_like(free, dtype=bool)
    found: list[set[tuple[int, int]]] = []
    rows, cols = free.shape
    for r in range(rows):
        for c in range(cols):
            if not free[r, c] or seen[r, c]:
                continue
            part = {(r, c)}
            seen[r, c] = True
            queue = deque([(r, c)])
            while queue:
                a, b = queue.popleft()
                for da, db in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                    na, nb = a + da, b + db
                    if 0 <= na < rows and 0 <= nb < cols and free[na, nb] and not seen[na, nb]:
                        seen[na, nb] = True
                        part.add((na, nb))
                        queue.append((na, nb))
            found.append(part)
    return found


def write_bag(
    path: Path,
    kind: str,
    messages: dict[str, tuple[str, list[tuple[int, float, float]]]],
    log_times: dict[str, list[int]] | None = None,
) -> Path:
    """A bag of ``kind`` ros1 / sqlite3 / mcap: per topic, (type, [(stamp ns, x, y), ...]).

    ``log_times`` gives a topic's log (receive) times when they differ from the header stamps.
    Types: ``nav_msgs/msg/Odometry``, ``geometry_msgs/msg/PoseStamped``,
    ``geometry_msgs/msg/PoseWithCovarianceStamped``, ``std_msgs/msg/String`` (not a pose).
    """
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if kind != "ros1" else Stores.ROS1_NOETIC)
    types: Any = store.types
    time_type = types["builtin_interfaces/msg/Time"]
    header = types["std_msgs/msg/Header"]
    pose_type = types["geometry_msgs/msg/Pose"]
    point = types["geometry_msgs/msg/Point"]
    quaternion = types["geometry_msgs/msg/Quaternion"]
    covariance = types["geometry_msgs/msg/PoseWithCovariance"]
    twist_cov = types["geometry_msgs/msg/TwistWithCovariance"]
    twist = types["geometry_msgs/msg/Twist"]
    vector = types["geometry_msgs/msg/Vector3"]

    def make(msgtype: str, ns: int, x: float, y: float) -> Any:
        stamp = time_type(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
        head = (
            header(seq=0, stamp=stamp, frame_id="odom")
            if kind == "ros1"
            else header(stamp=stamp, frame_id="odom")
        )
        pose = pose_type(
            position=point(x=x, y=y, z=0.0), orientation=quaternion(x=0.0, y=0.0, z=0.0, w=1.0)
        )
        cov = covariance(pose=pose, covariance=np.zeros(36))
        if msgtype == "nav_msgs/msg/Odometry":
            zero = vector(x=0.0, y=0.0, z=0.0)
            return types[msgtype](
                header=head,
                child_frame_id="base_link",
                pose=cov,
                twist=twist_cov(twist=twist(linear=zero, angular=zero), covariance=np.zeros(36)),
            )
        if msgtype == "geometry_msgs/msg/PoseStamped":
            return types[msgtype](header=head, pose=pose)
        if msgtype == "geometry_msgs/msg/PoseWithCovarianceStamped":
            return types[msgtype](header=head, pose=cov)
        return types[msgtype](data=f"{x},{y}")

    if kind == "ros1":
        from rosbags.rosbag1 import Writer as Writer1

        with Writer1(path) as writer1:
            for topic, (msgtype, rows) in messages.items():
                connection = writer1.add_connection(topic, msgtype, typestore=store)
                logged = (log_times or {}).get(topic) or [ns for ns, _, _ in rows]
                for (ns, x, y), log_ns in zip(rows, logged, strict=True):
                    data = store.serialize_ros1(make(msgtype, ns, x, y), msgtype)
                    writer1.write(connection, log_ns, data)
        return path
    from rosbags.rosbag2 import StoragePlugin, Writer

    plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        for topic, (msgtype, rows) in messages.items():
            connection = writer.add_connection(topic, msgtype, typestore=store)
            logged = (log_times or {}).get(topic) or [ns for ns, _, _ in rows]
            for (ns, x, y), log_ns in zip(rows, logged, strict=True):
                data = store.serialize_cdr(make(msgtype, ns, x, y), msgtype)
                writer.write(connection, log_ns, data)
    return path
