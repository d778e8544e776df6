"""Verify a long log in constant memory: read it in chunks, keep only the samples that shape it.

The verifier's answer depends on the trajectory through its *label word* (which regions the
robot is in, piece by piece; the semantics is stutter-invariant), on where and when the path
crosses a region's or the free space's boundary, and on its first and last samples.  A sample
strictly inside a disc around an earlier kept sample (the *anchor*) that touches no such
boundary changes none of these: the path from the anchor through it stays in the disc, so in
one cell of the map, and so does the straight shortcut from the anchor to the last sample
inside the disc.  :class:`Reducer` therefore keeps

* the first and the last sample,
* every sample where the path leaves the current anchor's disc (and the last one inside it,
  which becomes the next anchor),

so every segment that meets a boundary is kept as it was logged, with its end samples, and every
dropped stretch is replaced by a shortcut inside one cell.  The disc's radius is the anchor's
distance to the nearest boundary of a region the task mentions, or of the free space less the
body radius, minus a rounding margin.  :func:`verify_log` runs :func:`tlmpc.verify.verify_trace`
on the kept samples: the verdict, every conjunct's verdict and progress, and every violation
(times, places, durations) are those of the whole log (a property test compares them).  The
robustness is the kept trajectory's, and the certificate is the kept samples' (their motions
include the real one, and the log's own top speed is checked on every sample).

Memory is the current chunk plus the kept samples, which grow with the distance travelled
over the clearance, not with the sampling rate.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
import numpy.typing as npt

from tlmpc.base.errors import Diagnostic, UsageError
from tlmpc.verify import Verdict, declare_ending, from_document, verify_trace
from tlmpc.verify.clock import at
from tlmpc.verify.model import Certificate
from tlmpc.verify.robustness import speed_excess
from tlmpc.verify.samples import (
    MAX_MAGNITUDE,
    MAX_PER_KIND,
    CellPlace,
    SampleOrigin,
    as_whole_log,
    sample_diagnostics,
)
from tlmpc.verify.trace_input import certifying_speed

FloatArray = npt.NDArray[np.float64]

#: Clearance kept back from every boundary, relative to the map's extent: well above the
#: closed convention's rounding tolerance, so no dropped sample is labelled by rounding.
MARGIN = 1e-9

#: Samples per chunk of a bag (read whole by its reader, then streamed like a CSV).
BAG_CHUNK = 100_000


def _rings(document: Mapping[str, Any]) -> tuple[list[FloatArray], list[FloatArray]]:
    """The region outlines the task mentions, and the free space's outlines."""
    from tlmpc.ltl.parser import parse_ltl

    mentioned = parse_ltl(str(document["ltl"])).props()
    regions = [
        np.asarray(ring, dtype=np.float64)
        for name, ring in document["regions"].items()
        if name in mentioned
    ]
    workspace = document.get("workspace") or {}
    free: list[FloatArray] = []
    if workspace.get("boundary"):
        free.append(np.asarray(workspace["boundary"], dtype=np.float64))
        free.extend(np.asarray(h, dtype=np.float64) for h in workspace.get("holes") or [])
        for component in workspace.get("components") or []:
            free.append(np.asarray(component["boundary"], dtype=np.float64))
            free.extend(np.asarray(h, dtype=np.float64) for h in component.get("holes") or [])
    return regions, free


@dataclass(frozen=True, slots=True)
class _Edges:
    """The straight edges of some closed rings, each with an offset subtracted from its
    distance (the body radius for walls and holes, 0 for region boundaries), for the clearance
    of a point in one vectorised pass (a log keeps thousands of samples, each asks once)."""

    start_x: FloatArray
    start_y: FloatArray
    vector_x: FloatArray
    vector_y: FloatArray
    squares: FloatArray
    offsets: FloatArray

    @classmethod
    def of(cls, groups: Sequence[tuple[Sequence[FloatArray], float]]) -> _Edges | None:
        rings = [(ring, offset) for group, offset in groups for ring in group]
        if not rings:
            return None
        starts = np.vstack([ring for ring, _ in rings])
        vectors = np.vstack([np.roll(ring, -1, axis=0) - ring for ring, _ in rings])
        offsets = np.concatenate([np.full(len(ring), offset) for ring, offset in rings])
        squares = np.maximum(np.einsum("ij,ij->i", vectors, vectors), 1e-300)
        return cls(
            np.ascontiguousarray(starts[:, 0]),
            np.ascontiguousarray(starts[:, 1]),
            np.ascontiguousarray(vectors[:, 0]),
            np.ascontiguousarray(vectors[:, 1]),
            squares,
            offsets,
        )

    def reach(self, x: float, y: float) -> float:
        """The least distance from ``(x, y)`` to an edge, less that edge's offset."""
        dx, dy = x - self.start_x, y - self.start_y
        along = np.minimum(
            np.maximum((dx * self.vector_x + dy * self.vector_y) / self.squares, 0.0), 1.0
        )
        gap_x, gap_y = dx - along * self.vector_x, dy - along * self.vector_y
        return float((np.sqrt(gap_x * gap_x + gap_y * gap_y) - self.offsets).min())


class Reducer:
    """Keeps the samples of a stream that shape its verdict (see the module docstring)."""

    def __init__(self, document: Mapping[str, Any], *, pin_time: float | None = None) -> None:
        regions, free = _rings(document)
        self.radius = float(document.get("radius") or 0.0)
        self.edges = _Edges.of([(regions, 0.0), (free, self.radius)])
        extent = max((float(np.abs(r).max()) for r in (*regions, *free)), default=1.0)
        self.margin = MARGIN * max(1.0, extent)
        #: the first sample at or after this many seconds from the first one is kept (the start
        #: of a declared loop; counted from the log's start, as ``declare_ending`` counts)
        self.pin_time = pin_time
        self.origin = 0.0  # the first sample's time
        self.kept: list[FloatArray] = []
        self.anchor: FloatArray | None = None  # (t, x, y) of the current anchor, kept
        self.reach = 0.0  # the anchor's disc radius
        self.pending: FloatArray | None = None  # the last sample seen, inside the disc
        self.count = 0

    def clearance(self, point: FloatArray) -> float:
        """The radius of the open disc around ``point`` that touches no boundary."""
        x, y = float(point[1]), float(point[2])
        reach = math.inf if self.edges is None else self.edges.reach(x, y)
        return reach - self.margin

    def _keep(self, sample: FloatArray) -> None:
        if self.pin_time is not None and sample[0] - self.origin >= self.pin_time:
            self.pin_time = None
        self.kept.append(sample)
        self.anchor = sample
        self.reach = self.clearance(sample)
        self.pending = None

    def feed(self, samples: FloatArray) -> None:
        """The next samples ``(t, x, y)`` of the stream, in time order."""
        start = 0
        if self.anchor is None and len(samples):
            self.origin = float(samples[0][0])
            self._keep(samples[0].copy())
            start = 1
        self.count += len(samples)
        index = start
        window = 64
        while index < len(samples):
            assert self.anchor is not None
            stop = min(len(samples), index + window)
            block = samples[index:stop]
            offsets = np.hypot(block[:, 1] - self.anchor[1], block[:, 2] - self.anchor[2])
            # a sample at the anchor itself never leaves it, even where the anchor's disc is
            # empty (on a boundary): a robot standing still there keeps two samples
            out = ~((offsets < self.reach) | (offsets == 0.0))
            if self.pin_time is not None:
                out |= block[:, 0] - self.origin >= self.pin_time
            if not out.any():
                self.pending = samples[stop - 1].copy()
                index = stop
                window = min(window * 2, 1 << 16)
                continue
            first = index + int(np.argmax(out))
            if first > index:
                self.pending = samples[first - 1].copy()
            window = 64
            if self.pending is not None:
                # The last sample inside the disc becomes the anchor; test the leaver again.
                self._keep(self.pending)
                index = first
                continue
            self._keep(samples[first].copy())
            index = first + 1

    def finish(self) -> FloatArray:
        """The kept samples, the last sample of the stream included."""
        if self.pending is not None:
            self.kept.append(self.pending)
            self.pending = None
        if not self.kept:
            return np.zeros((0, 3))
        return np.vstack(self.kept)


@dataclass(frozen=True, slots=True, kw_only=True)
class StreamedVerdict:
    """A log's verdict from :func:`verify_log`, with what streaming saw of it."""

    verdict: Verdict
    samples: int
    kept: int
    start_time: float


class _CsvCells:
    """Where the cells of a streamed CSV log's samples are written, for its diagnostics
    (:data:`tlmpc.verify.samples.CellPlace`, by line number instead of sample index).

    The chunks carry their samples' line numbers, not the lines, so the log is read a second
    time, a block at a time, from the first problem placed on: a clean log never pays for it.
    The lines come from the readers' own line splitter and the columns from the live reader's
    (:meth:`tlmpc.importers.logs.CsvLines.column`), so a cell is placed as a whole log's is.
    Only the lines from the oldest one still asked about on are held (:meth:`forget_before`)."""

    def __init__(self, path: Path, columns: Sequence[str] | None, block_bytes: int) -> None:
        from tlmpc.importers.logs import CsvLines, LogLines

        self.path = path
        self.block_bytes = block_bytes
        self._splitter = LogLines(str(path))
        self._layout = CsvLines(str(path), columns)
        self._opened: contextlib.ExitStack | None = None
        self._stream: IO[bytes] | None = None
        self._first = 1  # the number of the first line held
        self._held: list[str] = []
        self._wanted = 1  # no line before this one is asked about
        self._ended = False

    def forget_before(self, number: int) -> None:
        """No line before line ``number`` will be asked about again."""
        self._wanted = max(self._wanted, number)
        drop = min(max(self._wanted - self._first, 0), len(self._held))
        del self._held[:drop]
        self._first += drop

    def place(self, number: int, cell: int) -> dict[str, int]:
        """The column of cell ``cell`` (0 time, 1 x, 2 y) of the sample on line ``number``."""
        while number >= self._first + len(self._held) and not self._ended:
            self._read_block()
        if not self._first <= number < self._first + len(self._held):
            return {}
        column = self._layout.column(self._held[number - self._first], cell)
        return {} if column is None else {"col": column}

    def _read_block(self) -> None:
        if self._stream is None:
            from tlmpc.io.inputs import open_regular

            self._opened = contextlib.ExitStack()
            self._stream = self._opened.enter_context(
                open_regular(self.path, code="M050", what="log")
            )
        data = self._stream.read(self.block_bytes)
        lines = self._splitter.feed(data) if data else self._splitter.finish()
        self._ended = not data
        number = self._first + len(self._held)
        for raw in lines:
            if self._layout.indices is None:
                # the header (or first row) the first reading accepted fixes the columns
                self._layout.parse(raw, number)
            number += 1
        self._held.extend(lines)
        self.forget_before(self._wanted)

    def close(self) -> None:
        """Close the second reading of the log, if it began."""
        if self._opened is not None:
            self._opened.close()


def _checked_chunks(
    chunks: Iterable[tuple[FloatArray, tuple[int, ...]]],
    file: str,
    cells: _CsvCells | None = None,
    origin: SampleOrigin | None = None,
) -> Iterator[FloatArray]:
    """The chunks, with the log's sample checks across chunk boundaries; every problem is
    collected (a few of each kind) and raised at the end, placed at its cell's column by
    ``cells`` when the log is a CSV."""
    previous: FloatArray | None = None
    previous_line: tuple[int, ...] = ()
    found: list[Diagnostic] = []
    counted = 0  # the samples before the current chunk, numbered as the whole log numbers them
    try:
        for samples, lines in chunks:
            # The previous chunk's last sample is joined for the order checks across the two;
            # one that is not finite or too large was reported with its own chunk, and then
            # the log gets no order checks (as a whole log's), so it is not checked again.
            joined, joined_lines = samples, lines
            if previous is not None and _usable(previous[0]):
                joined = np.vstack([previous, samples])
                joined_lines = previous_line + lines if lines else lines
            place: CellPlace | None = None
            if cells is not None and joined_lines:
                cells.forget_before(joined_lines[0])
                place = _by_line(cells, joined_lines)
            problems = sample_diagnostics(
                joined[:, 0],
                joined[:, 1],
                joined[:, 2],
                file=file,
                lines=joined_lines or None,
                first=counted - (len(joined) - len(samples)),
                place=place,
                origin=origin,
            )
            counted += len(samples)
            for problem in problems:
                if sum(d.code == problem.code for d in found) < MAX_PER_KIND:
                    found.append(problem)
            if len(samples):
                previous = samples[-1:].copy()
                previous_line = lines[-1:] if lines else ()
            if not found:
                yield samples
    finally:
        if cells is not None:
            cells.close()
    if previous is None and not found:
        found = sample_diagnostics(np.zeros(0), np.zeros(0), np.zeros(0), file=file)
    if found:
        raise UsageError(as_whole_log(found))


def _usable(sample: FloatArray) -> bool:
    """Whether a sample passes the checks of its own: finite, and not beyond the size the
    verifier takes (V003, V024)."""
    return bool(np.all(np.isfinite(sample)) and np.all(np.abs(sample) <= MAX_MAGNITUDE))


def _by_line(cells: _CsvCells, lines: Sequence[int]) -> CellPlace:
    """``cells`` asked by sample index, for samples written on ``lines``."""
    return lambda index, cell: cells.place(lines[index], cell) if index < len(lines) else {}


def _is_csv(path: Path) -> bool:
    """Whether ``path`` is read as a CSV log: chosen by name, as the whole reader chooses (a
    FIFO named .csv is a CSV log it refuses)."""
    from tlmpc.importers.logs import CSV_SUFFIXES

    return path.suffix.lower() in CSV_SUFFIXES and not path.is_dir()


def _log_chunks(
    path: Path,
    *,
    topic: str | None,
    columns: Sequence[str] | None,
    transform: tuple[float, float, float] | None,
    frame: str | None,
    block_bytes: int,
    whole_bag: bool,
) -> Iterator[tuple[FloatArray, tuple[int, ...]]]:
    from tlmpc.importers.logs import (
        apply_transform,
        iter_bag_chunks,
        iter_csv_chunks,
        read_log,
    )

    if _is_csv(path):
        if topic is not None or frame is not None:
            read_log(path, topic=topic, frame=frame)  # raises the reader's own diagnostic
        for chunk in iter_csv_chunks(path, columns, block_bytes):
            yield apply_transform(chunk.samples, transform), chunk.lines
        return
    if columns is not None or (frame is not None and transform is not None):
        read_log(path, columns=columns, transform=transform, frame=frame)  # the diagnostic
    # A bag whose stamps come in order streams chunk by chunk (iter_bag_chunks raises
    # BagOutOfOrder otherwise); ``whole_bag`` reads it whole and sorts it by stamp.
    if not whole_bag:
        for poses in iter_bag_chunks(path, topic, frame):
            yield apply_transform(poses, transform), ()
        return
    log = read_log(path, topic=topic, transform=transform, frame=frame)
    for start in range(0, max(len(log.samples), 1), BAG_CHUNK):
        yield log.samples[start : start + BAG_CHUNK], ()


def verify_log(
    path: Path,
    document: Mapping[str, Any],
    *,
    convention: str | None = None,
    topic: str | None = None,
    columns: Sequence[str] | None = None,
    transform: tuple[float, float, float] | None = None,
    frame: str | None = None,
    assume_stay: bool = False,
    loop_from: float | None = None,
    block_bytes: int = 1 << 22,
) -> StreamedVerdict:
    """Verify the log at ``path`` against ``document`` (a sample-less ``tlmpc.trace/1``, see
    :func:`tlmpc.verify.trace_input.mission_document`), a CSV log ``block_bytes`` bytes at
    a time, a bag a chunk of messages at a time (a bag whose stamps go back somewhere is
    verified again from the start, read whole and sorted)."""
    from tlmpc.importers.logs import BagOutOfOrder

    def attempt(whole_bag: bool) -> StreamedVerdict:
        return _verify_log(
            path,
            document,
            convention=convention,
            topic=topic,
            columns=columns,
            transform=transform,
            frame=frame,
            assume_stay=assume_stay,
            loop_from=loop_from,
            block_bytes=block_bytes,
            whole_bag=whole_bag,
        )

    try:
        return attempt(whole_bag=False)
    except BagOutOfOrder:
        return attempt(whole_bag=True)


def _verify_log(
    path: Path,
    document: Mapping[str, Any],
    *,
    convention: str | None,
    topic: str | None,
    columns: Sequence[str] | None,
    transform: tuple[float, float, float] | None,
    frame: str | None,
    assume_stay: bool,
    loop_from: float | None,
    block_bytes: int,
    whole_bag: bool,
) -> StreamedVerdict:
    file = str(path)
    reducer = Reducer(document, pin_time=loop_from)
    top_speed = 0.0
    max_gap = 0.0
    limit = certifying_speed(document.get("max_speed"))
    # the fastest gap beyond what max_speed allows (the verifier's speed check), and where
    violation: tuple[float, tuple[float, float]] | None = None
    last: FloatArray | None = None
    chunks = _log_chunks(
        path,
        topic=topic,
        columns=columns,
        transform=transform,
        frame=frame,
        block_bytes=block_bytes,
        whole_bag=whole_bag,
    )
    cells = _CsvCells(path, columns, block_bytes) if _is_csv(path) else None
    from tlmpc.importers.logs import SampleMessages

    # a bag's samples are named by their messages (looked up only for a diagnostic)
    origin = None if _is_csv(path) else SampleMessages(path, topic, by_stamp=whole_bag)
    for samples in _checked_chunks(chunks, file, cells, origin):
        joined = samples if last is None else np.vstack([last, samples])
        if len(joined) > 1:
            max_gap = max(max_gap, float(np.diff(joined[:, 0]).max()))
            steps = np.hypot(np.diff(joined[:, 1]), np.diff(joined[:, 2])) / np.diff(joined[:, 0])
            top_speed = max(top_speed, float(steps.max()))
            excess = None if limit is None else speed_excess(joined[:, 0], joined[:, 1:], limit)
            if excess is not None and excess.any():
                index = int(np.argmax(np.where(excess > 0.0, steps, -np.inf)))
                if violation is None or steps[index] > violation[0]:
                    where = (float(joined[index, 0]), float(joined[index + 1, 0]))
                    violation = (float(steps[index]), where)
        if len(samples):
            last = samples[-1:].copy()
        reducer.feed(samples)
    kept = reducer.finish()
    trace = from_document({**document, "points": kept.tolist()}, file=file, convention=convention)
    trace = declare_ending(trace, assume_stay=assume_stay, loop_from=loop_from)
    verdict = verify_trace(trace)
    verdict = dataclasses.replace(
        verdict,
        certificate=_raw_speed(
            dataclasses.replace(verdict.certificate, max_gap=max_gap),
            top_speed,
            violation,
            trace.start,
        ),
        stats={**verdict.stats, "samples": reducer.count, "kept_samples": len(kept)},
    )
    return StreamedVerdict(
        verdict=verdict, samples=reducer.count, kept=len(kept), start_time=float(kept[0, 0])
    )


def _raw_speed(
    certificate: Certificate,
    observed: float,
    violation: tuple[float, tuple[float, float]] | None,
    start: float,
) -> Certificate:
    """The certificate with the log's own top speed (every sample, not only the kept ones),
    refused where some gap moves faster than max_speed allows (``violation``: its speed and
    its stamps, written from the log's first sample at ``start`` as the verifier writes
    times)."""
    observed = max(observed, certificate.observed_speed)
    if certificate.max_speed is None or violation is None:
        return dataclasses.replace(certificate, observed_speed=observed)
    fastest, (begin, end) = violation
    return dataclasses.replace(
        certificate,
        certified=False,
        observed_speed=observed,
        margin=None,
        reason=f"the log moves at {fastest:.4g} m/s between {at(begin, start)} and "
        f"{at(end, start)}, faster than max_speed {certificate.max_speed:.4g}: the certificate's "
        "assumption does not hold",
    )
