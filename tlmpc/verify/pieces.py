"""Split a piecewise-linear trajectory into point and open pieces at region-boundary crossings.

Every segment between consecutive samples is cut where it meets a region's boundary (exact
segment–segment intersections, found through an STRtree of the boundary edges; a collinear
overlap contributes its end points).  The breakpoints become *point pieces*; the stretches
between them *open pieces*, labelled by the regions containing their midpoint.  How a point
piece is labelled is the boundary convention (see docs/semantics.md).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import shapely

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]

#: Parameters closer than this along one segment are one breakpoint.
MERGE = 1e-12


@dataclass(frozen=True, slots=True)
class Pieces:
    """Alternating pieces: ``is_point[k]``, time and position where each starts, labels."""

    is_point: BoolArray
    times: FloatArray
    positions: FloatArray  # (k, 2)
    labels: BoolArray  # (k, number of regions)
    loop_start: int | None  # index of the first piece of the loop (a point piece)


def _edges(polygons: Sequence[FloatArray]) -> tuple[FloatArray, FloatArray]:
    starts = np.concatenate(list(polygons))
    ends = np.concatenate([np.roll(p, -1, axis=0) for p in polygons])
    return starts, ends


def crossing_parameters(points: FloatArray, polygons: Sequence[FloatArray]) -> list[list[float]]:
    """For each segment, the sorted parameters in (0, 1) where it meets a polygon boundary."""
    segments = len(points) - 1
    found: list[list[float]] = [[] for _ in range(segments)]
    if segments <= 0 or not polygons:
        return found
    a0, a1 = points[:-1], points[1:]
    b0, b1 = _edges(polygons)
    seg_geoms = shapely.linestrings(np.stack([a0, a1], axis=1))
    edge_geoms = shapely.linestrings(np.stack([b0, b1], axis=1))
    tree = shapely.STRtree(edge_geoms)
    seg_idx, edge_idx = tree.query(seg_geoms, predicate="intersects")
    if len(seg_idx) == 0:
        return found
    p, r = a0[seg_idx], a1[seg_idx] - a0[seg_idx]
    q, s = b0[edge_idx], b1[edge_idx] - b0[edge_idx]
    denom = r[:, 0] * s[:, 1] - r[:, 1] * s[:, 0]
    qp = q - p
    scale = np.maximum(np.abs(r).sum(axis=1) * np.abs(s).sum(axis=1), 1e-300)
    parallel = np.abs(denom) <= 1e-14 * scale
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[:, 0] * s[:, 1] - qp[:, 1] * s[:, 0]) / denom
    for k in np.flatnonzero(~parallel):
        found[int(seg_idx[k])].append(float(t[k]))
    # Collinear overlaps: the overlap's end points along the segment.
    rr = np.maximum((r * r).sum(axis=1), 1e-300)
    for k in np.flatnonzero(parallel):
        t0 = float(((q[k] - p[k]) @ r[k]) / rr[k])
        t1 = float(((q[k] + s[k] - p[k]) @ r[k]) / rr[k])
        found[int(seg_idx[k])].extend([t0, t1])
    # only the segments that met a boundary (a long path has hundreds of thousands of others)
    for index in np.unique(seg_idx).tolist():
        values = found[index]
        inside = sorted(v for v in values if MERGE < v < 1.0 - MERGE)
        merged: list[float] = []
        for v in inside:
            if not merged or v - merged[-1] > MERGE:
                merged.append(v)
        found[index] = merged
    return found


def region_membership(
    regions: Sequence[shapely.Polygon], positions: FloatArray, *, closed: bool
) -> BoolArray:
    """(k, r): position k lies in region r (closed: boundary included; else interior)."""
    membership = np.zeros((len(positions), len(regions)), dtype=bool)
    if not len(positions) or not regions:
        return membership
    tree = shapely.STRtree(list(regions))
    point_geoms = shapely.points(positions)
    predicate = "intersects" if closed else "within"
    hits = tree.query(point_geoms, predicate=predicate)
    membership[hits[0], hits[1]] = True
    return membership


#: Under the closed convention a point within this distance (relative to the largest of its
#: own coordinates and the regions') of a region belongs to it: a crossing computed in
#: floating point lies on a slanted boundary only to rounding, on either side of it.  The
#: planner labels the start point by the same rule.
CLOSED_TOLERANCE = 1e-12


def boundary_membership(
    regions: Sequence[shapely.Polygon], outlines: Sequence[FloatArray], positions: FloatArray
) -> BoolArray:
    """(k, r): point k lies in the closure of region r, to rounding (:data:`CLOSED_TOLERANCE`)."""
    membership = np.zeros((len(positions), len(regions)), dtype=bool)
    if not len(positions) or not regions:
        return membership
    extent = max(float(np.abs(p).max()) for p in outlines)
    scale = np.maximum(np.abs(positions).max(axis=1), extent)
    tree = shapely.STRtree(list(regions))
    hits = tree.query(
        shapely.points(positions), predicate="dwithin", distance=CLOSED_TOLERANCE * scale
    )
    membership[hits[0], hits[1]] = True
    return membership


def build_pieces(
    times: FloatArray,
    points: FloatArray,
    loop_start: int | None,
    regions: Mapping[str, FloatArray],
    convention: str,
) -> Pieces:
    """The pieces of the trajectory and their labels under ``convention`` (right|closed)."""
    names = list(regions)
    polygons = [np.asarray(regions[n], dtype=np.float64) for n in names]
    shapes = [shapely.Polygon(p) for p in polygons]
    cuts = crossing_parameters(points, polygons)
    # Breakpoints: every sample and every crossing, in order (vectorised: the crossings of
    # segment i follow sample i).
    n = len(points)
    per_seg = np.array([len(c) for c in cuts] + [0] * (n - len(cuts)), dtype=np.int64)[:n]
    sample_idx = np.arange(n, dtype=np.int64) + np.concatenate(([0], np.cumsum(per_seg)[:-1]))
    count = n + int(per_seg.sum())
    bp_times = np.empty(count)
    bp_positions = np.empty((count, 2))
    bp_times[sample_idx] = times
    bp_positions[sample_idx] = points
    if count > n:
        seg = np.repeat(np.arange(n, dtype=np.int64), per_seg)
        sigma = np.fromiter((s for c in cuts for s in c), dtype=np.float64, count=count - n)
        rank = np.arange(count - n) - np.repeat(np.cumsum(per_seg) - per_seg, per_seg)
        slots = sample_idx[seg] + 1 + rank
        bp_times[slots] = times[seg] + sigma * (times[seg + 1] - times[seg])
        bp_positions[slots] = points[seg] + sigma[:, None] * (points[seg + 1] - points[seg])
    sample_bp = sample_idx.tolist()
    count = len(bp_times)
    mids = (bp_positions[:-1] + bp_positions[1:]) / 2.0 if count > 1 else np.zeros((0, 2))
    open_labels = region_membership(shapes, mids, closed=True)
    if convention == "closed":
        point_labels = boundary_membership(shapes, polygons, bp_positions)
    else:
        point_labels = np.empty((count, len(names)), dtype=bool)
        if count > 1:
            point_labels[:-1] = open_labels
        # The last sample: the robot stays there forever (finite trace), so it is in the
        # regions containing it; a loop's last sample is the wrap and is dropped below.
        point_labels[-1] = region_membership(shapes, bp_positions[-1:], closed=True)[0]
    # Interleave: point 0, open 0, point 1, open 1, ..., point last.
    kinds = np.zeros(2 * count - 1, dtype=bool)
    kinds[0::2] = True
    labels = np.empty((2 * count - 1, len(names)), dtype=bool)
    labels[0::2] = point_labels
    labels[1::2] = open_labels
    piece_times = np.empty(2 * count - 1)
    piece_times[0::2] = bp_times
    piece_times[1::2] = bp_times[:-1]
    piece_pos = np.empty((2 * count - 1, 2))
    piece_pos[0::2] = bp_positions
    piece_pos[1::2] = mids
    loop_piece = None
    if loop_start is not None:
        loop_piece = 2 * sample_bp[loop_start]
        # The last sample coincides (in label word) with the loop start: drop it.
        kinds, labels = kinds[:-1], labels[:-1]
        piece_times, piece_pos = piece_times[:-1], piece_pos[:-1]
    return Pieces(
        is_point=kinds, times=piece_times, positions=piece_pos, labels=labels, loop_start=loop_piece
    )


def merge_pieces(pieces: Pieces, convention: str) -> Pieces:
    """Merge neighbours that cannot be told apart (keeps the loop start and alternation)."""
    k = len(pieces.is_point)
    keep = np.ones(k, dtype=bool)
    labels = pieces.labels
    if convention == "right":
        # Half-open pieces: equal neighbouring labels are one piece (stutter invariance).
        same = np.all(labels[1:] == labels[:-1], axis=1)
        keep[1:] = ~same
    else:
        # Closed: an open-point-open triple with one label is one open piece.
        protected = set()
        if pieces.loop_start is not None:
            protected = {pieces.loop_start - 1, pieces.loop_start, pieces.loop_start + 1}
        for index in range(1, k - 1):
            if (
                pieces.is_point[index]
                and index not in protected
                and index + 1 not in protected
                and np.array_equal(labels[index - 1], labels[index])
                and np.array_equal(labels[index], labels[index + 1])
            ):
                keep[index] = False
                keep[index + 1] = False
    if pieces.loop_start is not None and convention == "right":
        keep[pieces.loop_start] = True
    new_loop = None if pieces.loop_start is None else int(keep[: pieces.loop_start].sum())
    return Pieces(
        is_point=pieces.is_point[keep],
        times=pieces.times[keep],
        positions=pieces.positions[keep],
        labels=labels[keep],
        loop_start=new_loop,
    )
