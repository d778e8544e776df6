"""Frame transforms from a bag's /tf and /tf_static (``tlmpc verify LOG --frame FRAME``).

Bags are written here with rosbags (ROS 1, ROS 2 sqlite3, MCAP); the oracle composes the
chain independently with 4x4 homogeneous matrices and scipy's rotations and Slerp.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from robot_data import require_shared
from scipy.spatial.transform import Rotation, Slerp

from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.importers.frames import TransformCollector
from tlmpc.importers.logs import read_log

FloatArray = npt.NDArray[np.float64]
KINDS = ("ros1", "sqlite3", "mcap")


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


# --- the independent oracle ------------------------------------------------------------------

Sample = tuple[int, FloatArray, FloatArray]  # stamp ns, translation (3,), quaternion xyzw (4,)


def matrix(translation: FloatArray, quaternion: FloatArray) -> FloatArray:
    result = np.eye(4)
    result[:3, :3] = Rotation.from_quat(quaternion).as_matrix()
    result[:3, 3] = translation
    return result


def oracle_edge(samples: list[Sample], stamp: int) -> FloatArray:
    """T_parent<-child at ``stamp``: lerp of translations, scipy Slerp of rotations."""
    if len(samples) == 1:
        return matrix(samples[0][1], samples[0][2])
    times = np.array([s[0] for s in samples], dtype=np.float64)
    k = int(np.searchsorted(times, stamp, side="right")) - 1
    k = min(max(k, 0), len(samples) - 2)
    t0, t1 = samples[k][0], samples[k + 1][0]
    u = (stamp - t0) / (t1 - t0)
    translation = (1 - u) * samples[k][1] + u * samples[k + 1][1]
    slerp = Slerp([0.0, 1.0], Rotation.from_quat([samples[k][2], samples[k + 1][2]]))
    result = np.eye(4)
    result[:3, :3] = slerp([u]).as_matrix()[0]
    result[:3, 3] = translation
    return result


def random_quaternion(rng: np.random.Generator, tilt: float) -> FloatArray:
    """Mostly a yaw, with roll and pitch up to ``tilt`` radians."""
    roll, pitch = rng.uniform(-tilt, tilt, 2)
    yaw = rng.uniform(-np.pi, np.pi)
    quaternion: FloatArray = Rotation.from_euler("xyz", [roll, pitch, yaw]).as_quat()
    return quaternion


# --- bags with tf, written with rosbags ------------------------------------------------------

TF_DEFINITION = "geometry_msgs/TransformStamped[] transforms\n"


def write_tf_bag(
    path: Path,
    kind: str,
    poses: list[tuple[int, float, float, float]],
    pose_frame: str,
    tf: dict[tuple[str, str], list[Sample]],
    static: dict[tuple[str, str], Sample],
) -> Path:
    """A bag with Odometry on /odom (in ``pose_frame``), /tf and /tf_static."""
    from rosbags.typesys import Stores, get_typestore
    from rosbags.typesys.store import Typestore

    store: Typestore = get_typestore(Stores.ROS1_NOETIC if kind == "ros1" else Stores.ROS2_HUMBLE)
    if "tf2_msgs/msg/TFMessage" not in store.types:
        from rosbags.typesys import get_types_from_msg

        store.register(get_types_from_msg(TF_DEFINITION, "tf2_msgs/msg/TFMessage"))
    types: Any = store.types

    def header(ns: int, frame: str) -> Any:
        stamp = types["builtin_interfaces/msg/Time"](
            sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000
        )
        if kind == "ros1":
            return types["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame)
        return types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    vector = types["geometry_msgs/msg/Vector3"]
    quaternion = types["geometry_msgs/msg/Quaternion"]

    def transform(parent: str, child: str, sample: Sample) -> Any:
        ns, t, q = sample
        return types["geometry_msgs/msg/TransformStamped"](
            header=header(ns, parent),
            child_frame_id=child,
            transform=types["geometry_msgs/msg/Transform"](
                translation=vector(x=t[0], y=t[1], z=t[2]),
                rotation=quaternion(x=q[0], y=q[1], z=q[2], w=q[3]),
            ),
        )

    def odometry(ns: int, x: float, y: float, z: float) -> Any:
        pose = types["geometry_msgs/msg/Pose"](
            position=types["geometry_msgs/msg/Point"](x=x, y=y, z=z),
            orientation=quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
        )
        zero = vector(x=0.0, y=0.0, z=0.0)
        return types["nav_msgs/msg/Odometry"](
            header=header(ns, pose_frame),
            child_frame_id="base_link",
            pose=types["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
            twist=types["geometry_msgs/msg/TwistWithCovariance"](
                twist=types["geometry_msgs/msg/Twist"](linear=zero, angular=zero),
                covariance=np.zeros(36),
            ),
        )

    messages: list[tuple[str, str, int, Any]] = []
    for ns, x, y, z in poses:
        messages.append(("/odom", "nav_msgs/msg/Odometry", ns, odometry(ns, x, y, z)))
    tf_type = "tf2_msgs/msg/TFMessage"
    for (parent, child), samples in tf.items():
        for sample in samples:
            message = types[tf_type](transforms=[transform(parent, child, sample)])
            messages.append(("/tf", tf_type, sample[0], message))
    if static:
        message = types[tf_type](transforms=[transform(p, c, s) for (p, c), s in static.items()])
        first = min(ns for ns, *_ in poses)
        messages.append(("/tf_static", tf_type, first, message))
    messages.sort(key=lambda m: m[2])
    if kind == "ros1":
        from rosbags.rosbag1 import Writer as Writer1

        with Writer1(path) as writer1:
            connections: dict[str, Any] = {}
            for topic, msgtype, ns, message in messages:
                if topic not in connections:
                    connections[topic] = writer1.add_connection(topic, msgtype, typestore=store)
                writer1.write(connections[topic], ns, store.serialize_ros1(message, msgtype))
        return path
    from rosbags.rosbag2 import StoragePlugin, Writer

    plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        connections = {}
        for topic, msgtype, ns, message in messages:
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(connections[topic], ns, store.serialize_cdr(message, msgtype))
    return path


def bag_path(directory: Path, kind: str, name: str = "log") -> Path:
    return directory / (f"{name}.bag" if kind == "ros1" else name)


SECOND = 1_000_000_000
T0 = 1_700_000_000 * SECOND  # a real epoch: stamps far from zero


def scenario(
    rng: np.random.Generator, tilt: float
) -> tuple[
    list[tuple[int, float, float, float]],
    dict[tuple[str, str], list[Sample]],
    dict[tuple[str, str], Sample],
]:
    """Poses in odom over 5 s; map->odom at 1 Hz, odom->base_link at 4 Hz; map->gps static."""
    stamps = sorted({T0 + int(v) for v in rng.integers(SECOND // 10, 5 * SECOND, 40)})
    poses = [
        (int(t), *rng.uniform(-5, 5, 2).tolist(), float(rng.uniform(-0.2, 0.2))) for t in stamps
    ]
    map_odom = [
        (T0 + k * SECOND, rng.uniform(-3, 3, 3), random_quaternion(rng, tilt)) for k in range(6)
    ]
    odom_base = [
        (T0 + k * SECOND // 4, rng.uniform(-3, 3, 3), random_quaternion(rng, tilt))
        for k in range(21)
    ]
    gps = (T0, rng.uniform(-3, 3, 3), random_quaternion(rng, tilt))
    return (
        [(t, x, y, z) for t, x, y, z in poses],
        {("map", "odom"): map_odom, ("odom", "base_link"): odom_base},
        {("map", "gps"): gps},
    )


def oracle_samples(
    poses: list[tuple[int, float, float, float]],
    tf: dict[tuple[str, str], list[Sample]],
    static: dict[tuple[str, str], Sample],
    target: str,
) -> FloatArray:
    """Poses in odom expressed in ``target`` (map, gps or base_link), composed by hand."""
    rows = []
    for ns, x, y, z in poses:
        map_odom = oracle_edge(tf[("map", "odom")], ns)
        odom_base = oracle_edge(tf[("odom", "base_link")], ns)
        map_gps = matrix(static[("map", "gps")][1], static[("map", "gps")][2])
        to_target = {
            "map": map_odom,
            "gps": np.linalg.inv(map_gps) @ map_odom,
            "base_link": np.linalg.inv(odom_base),
        }[target]
        point = to_target @ np.array([x, y, z, 1.0])
        rows.append((ns / 1e9, point[0], point[1]))
    return np.asarray(rows)


# --- tests --------------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("target", ["map", "gps", "base_link"])
def test_poses_are_expressed_in_the_chosen_frame(tmp_path: Path, kind: str, target: str) -> None:
    rng = np.random.default_rng(7)
    poses, tf, static = scenario(rng, tilt=0.3)
    path = write_tf_bag(bag_path(tmp_path, kind), kind, poses, "odom", tf, static)
    log = read_log(path, frame=target)
    expected = oracle_samples(poses, tf, static, target)
    assert log.samples[:, 0].tolist() == expected[:, 0].tolist()
    np.testing.assert_allclose(log.samples[:, 1:], expected[:, 1:], rtol=0, atol=1e-9)
    # the default stays the poses' own frame
    own = read_log(path)
    assert own.samples[:, 1:].tolist() == [[x, y] for _, x, y, _ in poses]


def test_every_storage_gives_the_same_samples(tmp_path: Path) -> None:
    rng = np.random.default_rng(11)
    poses, tf, static = scenario(rng, tilt=0.0)
    logs = [
        read_log(
            write_tf_bag(bag_path(tmp_path, kind, kind), kind, poses, "/odom", tf, static),
            frame="map",
        ).samples
        for kind in KINDS
    ]
    assert logs[0].tolist() == logs[1].tolist() == logs[2].tolist()


@settings(deadline=None, max_examples=60)
@given(
    seed=st.integers(0, 2**32 - 1),
    tilt=st.sampled_from([0.0, 0.5, 1.5]),
    samples=st.integers(1, 6),
)
def test_chain_composition_matches_homogeneous_matrices(
    seed: int, tilt: float, samples: int
) -> None:
    """The frame tree alone (no bag): a -> b dynamic, b -> c static, a -> d dynamic."""
    rng = np.random.default_rng(seed)
    collector = TransformCollector("t")
    edges: dict[tuple[str, str], list[Sample]] = {}
    for parent, child in (("a", "b"), ("a", "d")):
        stamps = sorted(set(rng.integers(0, 10 * SECOND, samples).tolist()))
        edges[(parent, child)] = [
            (int(t), rng.uniform(-2, 2, 3), random_quaternion(rng, tilt)) for t in stamps
        ]
        for ns, translation, quaternion in edges[(parent, child)]:
            collector.add(
                parent=parent,
                child=child,
                stamp=ns,
                translation=(translation[0], translation[1], translation[2]),
                rotation=(quaternion[0], quaternion[1], quaternion[2], quaternion[3]),
                static=False,
            )
    fixed: Sample = (0, rng.uniform(-2, 2, 3), random_quaternion(rng, tilt))
    collector.add(
        parent="b",
        child="c",
        stamp=0,
        translation=(fixed[1][0], fixed[1][1], fixed[1][2]),
        rotation=(fixed[2][0], fixed[2][1], fixed[2][2], fixed[2][3]),
        static=True,
    )
    tree = collector.tree()
    low = max(edges[("a", "b")][0][0], edges[("a", "d")][0][0])
    high = min(edges[("a", "b")][-1][0], edges[("a", "d")][-1][0])
    if low > high:
        with pytest.raises(UsageError) as caught:
            tree.express("d", "c", np.array([low], dtype=np.int64), np.zeros((1, 3)))
        assert caught.value.diagnostics[0].code == "M104"
        return
    between = rng.integers(low, high + 1, 10)
    times = np.unique(np.concatenate([np.array([low, high]), between])).astype(np.int64)
    points = rng.uniform(-3, 3, (len(times), 3))
    got = tree.express("d", "c", times, points)
    for k, ns in enumerate(times.tolist()):
        a_b = oracle_edge(edges[("a", "b")], ns)
        a_d = oracle_edge(edges[("a", "d")], ns)
        d_c = np.linalg.inv(a_d) @ a_b @ matrix(fixed[1], fixed[2])
        expected = d_c @ np.append(points[k], 1.0)
        np.testing.assert_allclose(got[k], expected[:3], rtol=0, atol=1e-9)


@pytest.mark.parametrize("kind", KINDS)
def test_missing_tf_and_uncovered_times_get_diagnostics(tmp_path: Path, kind: str) -> None:
    rng = np.random.default_rng(3)
    poses, tf, static = scenario(rng, tilt=0.0)
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nworkspace: {boundary: {rect: [-100, -100, 100, 100]}}\n"
        "regions: {a: {rect: [0, 0, 1, 1]}}\nrobot: {start: [0, 0]}\ntask: [visit a]\n"
    )

    def verify(path: Path, *extra: str) -> tuple[int, str]:
        code, out, err = run("verify", str(path), "--mission", str(mission), *extra)
        return code, out + err

    (tmp_path / "none").mkdir()
    bare = write_tf_bag(bag_path(tmp_path / "none", kind), kind, poses, "odom", {}, {})
    code, text = verify(bare, "--frame", "map")
    assert code == 2
    assert "error[M102]" in text
    assert "Traceback" not in text
    (tmp_path / "chain").mkdir()
    chained = write_tf_bag(bag_path(tmp_path / "chain", kind), kind, poses, "odom", tf, static)
    code, text = verify(chained, "--frame", "earth")
    assert code == 2
    assert "error[M103]" in text
    assert "'earth'" in text
    # /tf that starts after the first pose: never extrapolated
    late = {key: [s for s in samples if s[0] > T0 + SECOND] for key, samples in tf.items()}
    (tmp_path / "late").mkdir()
    short = write_tf_bag(bag_path(tmp_path / "late", kind), kind, poses, "odom", late, static)
    code, text = verify(short, "--frame", "map")
    assert code == 2
    assert "error[M104]" in text
    assert "map -> odom" in text
    code, text = verify(chained, "--frame", "map", "--transform", "0,0,0")
    assert code == 2
    assert "error[M105]" in text
    # the poses' own frame needs no tf
    assert verify(bare, "--frame", "odom")[0] in (0, 1, 4)


def test_frame_on_a_csv_log_is_refused(tmp_path: Path) -> None:
    log = tmp_path / "log.csv"
    log.write_text("t,x,y\n0,0,0\n1,1,1\n")
    with pytest.raises(UsageError) as caught:
        read_log(log, frame="map")
    assert caught.value.diagnostics[0].code == "M105"


def test_a_zero_quaternion_is_refused() -> None:
    collector = TransformCollector("t")
    with pytest.raises(UsageError) as caught:
        collector.add(
            parent="map",
            child="odom",
            stamp=0,
            translation=(0.0, 0.0, 0.0),
            rotation=(0.0, 0.0, 0.0, 0.0),
            static=True,
        )
    assert caught.value.diagnostics[0].code == "M106"


def test_a_frame_with_two_parents_is_refused() -> None:
    collector = TransformCollector("t")
    unit = (0.0, 0.0, 0.0, 1.0)
    collector.add(
        parent="map", child="odom", stamp=0, translation=(0, 0, 0), rotation=unit, static=True
    )
    with pytest.raises(UsageError) as caught:
        collector.add(
            parent="earth", child="odom", stamp=0, translation=(0, 0, 0), rotation=unit, static=True
        )
    assert caught.value.diagnostics[0].code == "M103"


def test_the_real_bags_have_no_tf(tmp_path: Path) -> None:
    """The real Jackal bag logs odometry in odom without /tf: --frame map says so; --frame odom
    is the poses' own frame and changes nothing."""
    bag = require_shared("bags/jackal_odometry.bag")
    with pytest.raises(UsageError) as caught:
        read_log(bag, frame="map")
    assert caught.value.diagnostics[0].code == "M102"
    assert read_log(bag, frame="odom").samples.tolist() == read_log(bag).samples.tolist()
