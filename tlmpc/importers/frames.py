"""Frame transforms from a bag's ``/tf`` and ``/tf_static``: poses re-expressed in another frame.

A bag's ``tf2_msgs/TFMessage`` messages give, per child frame, its pose in its parent frame:
on ``/tf_static`` once for all times, on ``/tf`` at stamped instants.  Together they form a tree
of frames.  To express a pose logged in frame ``S`` (its header's ``frame_id``, e.g. ``odom``) in
frame ``F`` (e.g. ``map``), the chain from ``S`` up to the lowest common ancestor of ``S`` and ``F``
and down to ``F`` is composed at the pose's stamp, as tf2 does: a dynamic transform is
interpolated between the two samples that bracket the stamp (translation linearly, rotation by
spherical linear interpolation of the quaternions); a stamp outside a dynamic transform's samples
is an error (tf2's extrapolation error), never extrapolated.

The composition is done in 3D (rotation matrices from the quaternions) and applied to the pose's
3D position; the sample is the x, y of the result.  This is the SE(2) projection: a planar robot's
position on the map's ground plane, exact also when a transform in the chain has roll or pitch
(a tilted odometry frame), where composing yaw-only transforms would not be.

Frame names are compared without a leading ``/`` (ROS 1 bags often write ``/odom``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from tlmpc.base.errors import UsageError, error

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

TF_TYPE = "tf2_msgs/msg/TFMessage"


def frame_name(name: str) -> str:
    """A frame id as tf2 compares it (without a leading slash)."""
    return name.lstrip("/")


@dataclass(frozen=True, slots=True, kw_only=True)
class Edge:
    """The pose of ``child`` in ``parent``: one sample if static, else stamped samples."""

    parent: str
    child: str
    static: bool
    stamps: IntArray = field(compare=False)  # (k,) nanoseconds, increasing (dynamic only)
    translations: FloatArray = field(compare=False)  # (k, 3)
    rotations: FloatArray = field(compare=False)  # (k, 4) unit quaternions x, y, z, w


@dataclass(slots=True)
class _Samples:
    parent: str
    static: bool
    rows: list[tuple[int, float, float, float, float, float, float, float]]


def _fail(code: str, message: str, file: str, hint: str | None = None) -> UsageError:
    return UsageError(error(code, message, hint=hint, file=file))


class TransformCollector:
    """Collects the transforms of a bag's TF messages, then builds the tree of frames."""

    def __init__(self, file: str) -> None:
        self.file = file
        self._edges: dict[str, _Samples] = {}

    def add(
        self,
        *,
        parent: str,
        child: str,
        stamp: int,
        translation: tuple[float, float, float],
        rotation: tuple[float, float, float, float],
        static: bool,
    ) -> None:
        """One ``geometry_msgs/TransformStamped`` (``static``: from ``/tf_static``)."""
        parent, child = frame_name(parent), frame_name(child)
        norm = float(np.linalg.norm(rotation))
        if not np.isfinite(norm) or norm < 1e-9 or not all(np.isfinite(translation)):
            raise _fail(
                "M106",
                f"the transform {parent} -> {child} at t={stamp / 1e9:.9g} s is not a rigid "
                "transform (a zero or non-finite quaternion or translation)",
                self.file,
            )
        known = self._edges.get(child)
        if known is not None and known.parent != parent:
            raise _fail(
                "M103",
                f"frame {child!r} has two parents in the bag's tf: {known.parent!r} and {parent!r}",
                self.file,
                hint="tf must form a tree: each frame has one parent",
            )
        qx, qy, qz, qw = (v / norm for v in rotation)
        row = (stamp, translation[0], translation[1], translation[2], qx, qy, qz, qw)
        if known is None or (static and not known.static):
            # a static transform replaces dynamic samples of the same edge (tf2 keeps both,
            # but a bag that publishes an edge both ways is the static one's intent)
            self._edges[child] = _Samples(parent=parent, static=static, rows=[row])
        elif known.static:
            if static:
                known.rows = [row]  # the latest static transform wins, as in tf2
        else:
            known.rows.append(row)

    def tree(self) -> FrameTree:
        """The tree of frames (each dynamic edge's samples sorted, repeated stamps once)."""
        edges: dict[str, Edge] = {}
        for child, samples in self._edges.items():
            rows = sorted(samples.rows, key=lambda r: r[0])
            kept = [r for i, r in enumerate(rows) if i == 0 or r[0] != rows[i - 1][0]]
            array = np.asarray(kept, dtype=np.float64).reshape(-1, 8)
            edges[child] = Edge(
                parent=samples.parent,
                child=child,
                static=samples.static,
                stamps=np.asarray([r[0] for r in kept], dtype=np.int64),
                translations=array[:, 1:4].copy(),
                rotations=array[:, 4:8].copy(),
            )
        return FrameTree(edges=edges, file=self.file)


def quaternion_matrices(q: FloatArray) -> FloatArray:
    """Rotation matrices (n, 3, 3) of unit quaternions (n, 4) given as x, y, z, w."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )


def slerp(q0: FloatArray, q1: FloatArray, u: FloatArray) -> FloatArray:
    """Spherical linear interpolation of unit quaternions (n, 4) at fractions ``u`` (n,)."""
    dot = np.sum(q0 * q1, axis=1)
    q1 = np.where((dot < 0)[:, None], -q1, q1)  # the shorter arc
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    small = theta < 1e-9
    sin = np.where(small, 1.0, np.sin(theta))
    a = np.where(small, 1.0 - u, np.sin((1.0 - u) * theta) / sin)
    b = np.where(small, u, np.sin(u * theta) / sin)
    q = a[:, None] * q0 + b[:, None] * q1
    result: FloatArray = q / np.linalg.norm(q, axis=1, keepdims=True)
    return result


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameTree:
    """The frames of a bag and the transforms between them."""

    edges: Mapping[str, Edge]
    file: str

    def frames(self) -> list[str]:
        """Every frame named by a transform, sorted."""
        names = set(self.edges) | {e.parent for e in self.edges.values()}
        return sorted(names)

    def _ancestors(self, frame: str) -> list[str]:
        chain = [frame]
        while chain[-1] in self.edges:
            parent = self.edges[chain[-1]].parent
            if parent in chain:
                raise _fail(
                    "M103",
                    f"the bag's tf has a cycle through {parent!r}",
                    self.file,
                    hint="tf must form a tree",
                )
            chain.append(parent)
        return chain

    def _edge_at(self, edge: Edge, stamps: IntArray) -> tuple[FloatArray, FloatArray]:
        """The edge's rotation matrices and translations (parent <- child) at ``stamps``."""
        n = len(stamps)
        if edge.static:
            rotation = np.repeat(quaternion_matrices(edge.rotations[:1]), n, axis=0)
            return rotation, np.repeat(edge.translations[:1], n, axis=0)
        first, last = int(edge.stamps[0]), int(edge.stamps[-1])
        outside = (stamps < first) | (stamps > last)
        if outside.any():
            bad = int(stamps[np.argmax(outside)])
            raise _fail(
                "M104",
                f"the transform {edge.parent} -> {edge.child} is known from t={first / 1e9:.9g} s "
                f"to t={last / 1e9:.9g} s ({len(edge.stamps)} samples), but the log has a pose "
                f"at t={bad / 1e9:.9g} s ({int(outside.sum())} poses outside)",
                self.file,
                hint="transforms are interpolated, never extrapolated: record /tf over the "
                "whole log, or use --transform X,Y,YAW for a fixed transform",
            )
        if len(edge.stamps) == 1:  # every stamp equals the one sample's
            upper = lower = np.zeros(n, dtype=np.int64)
            u = np.zeros(n)
        else:
            upper = np.clip(np.searchsorted(edge.stamps, stamps), 1, len(edge.stamps) - 1)
            lower = upper - 1
            t0 = edge.stamps[lower]
            t1 = edge.stamps[upper]
            # integer nanoseconds subtracted before converting: exact for any epoch
            u = (stamps - t0).astype(np.float64) / (t1 - t0).astype(np.float64)
        translation = (1.0 - u)[:, None] * edge.translations[lower] + u[
            :, None
        ] * edge.translations[upper]
        rotation = quaternion_matrices(slerp(edge.rotations[lower], edge.rotations[upper], u))
        return rotation, translation

    def _up(self, path: Sequence[str], stamps: IntArray) -> tuple[FloatArray, FloatArray]:
        """T_last<-first along ``path`` (each frame the child of the next), at ``stamps``."""
        n = len(stamps)
        rotation = np.repeat(np.eye(3)[None], n, axis=0)
        translation = np.zeros((n, 3))
        for child in path[:-1]:
            r, t = self._edge_at(self.edges[child], stamps)
            translation = np.einsum("nij,nj->ni", r, translation) + t
            rotation = r @ rotation
        return rotation, translation

    def lookup(self, target: str, source: str, stamps: IntArray) -> tuple[FloatArray, FloatArray]:
        """Rotations (n, 3, 3) and translations (n, 3) of T_target<-source at ``stamps`` (ns)."""
        target, source = frame_name(target), frame_name(source)
        up_source = self._ancestors(source)
        up_target = self._ancestors(target)
        common = next((f for f in up_source if f in up_target), None)
        if common is None:
            known = ", ".join(self.frames()) or "(none)"
            raise _fail(
                "M103",
                f"no chain of transforms from frame {source!r} to frame {target!r} in the "
                "bag's /tf and /tf_static",
                self.file,
                hint=f"frames with transforms: {known}; "
                + " ".join(f"{e.parent}->{e.child}" for e in self.edges.values()),
            )
        to_common = up_source[: up_source.index(common) + 1]
        from_target = up_target[: up_target.index(common) + 1]
        r_s, t_s = self._up(to_common, stamps)  # T_common<-source
        r_t, t_t = self._up(from_target, stamps)  # T_common<-target
        inverse = np.transpose(r_t, (0, 2, 1))
        rotation = inverse @ r_s
        translation = np.einsum("nij,nj->ni", inverse, t_s - t_t)
        return rotation, translation

    def express(
        self, target: str, source: str, stamps: IntArray, positions: FloatArray
    ) -> FloatArray:
        """3D ``positions`` (n, 3) given in ``source`` at ``stamps``, expressed in ``target``."""
        if frame_name(target) == frame_name(source):
            return positions.copy()
        rotation, translation = self.lookup(target, source, stamps)
        result: FloatArray = np.einsum("nij,nj->ni", rotation, positions) + translation
        return result
