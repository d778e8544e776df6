"""The verdict: truth (two- or three-valued), per-conjunct progress, every violation,
robustness that agrees with the verdict, and the certificate for the real robot."""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Callable, Collection, Iterator, Mapping, Set
from typing import Any

import numpy as np
import numpy.typing as npt
import shapely

from tlmpc.base.errors import UsageError, error
from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedUntil,
    Formula,
    Globally,
    bounded_operators,
)
from tlmpc.ltl.printer import to_text
from tlmpc.verify.blame import Prefixes, assume_guarantee
from tlmpc.verify.clock import Clock, since_first
from tlmpc.verify.dense import DenseSemantics, Domain, UnrollTooLong
from tlmpc.verify.evaluate import Value, truth_atoms
from tlmpc.verify.model import (
    AssumeGuarantee,
    Certificate,
    ConjunctReport,
    Counterexample,
    Outcome,
    PartVerdict,
    Verdict,
    Violation,
)
from tlmpc.verify.pieces import Pieces, build_pieces, merge_pieces, region_membership
from tlmpc.verify.progress import Timeline, conjunct_reports, runs, timed_progress
from tlmpc.verify.robustness import piece_atoms, speed_excess, tube_atoms, tube_radii
from tlmpc.verify.semantics import PieceEnding, Semantics, Timing
from tlmpc.verify.signals import Signal, change_times, counted_from, signal_labels, with_cuts
from tlmpc.verify.time_robustness import (
    conjunction_robustness,
    horizon,
    reach,
    tightest_deadline,
    time_robustness,
)
from tlmpc.verify.trace_input import TraceInput

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


def _conjuncts(formula: Formula) -> list[Formula]:
    return list(formula.args) if isinstance(formula, And) else [formula]


def _outcome(lo: float, hi: float) -> Outcome:
    if lo > 0:
        return "satisfied"
    if hi < 0:
        return "violated"
    return "inconclusive"


def _last_point_unknown(
    trace: TraceInput, pieces: Pieces, regions: dict[str, FloatArray]
) -> BoolArray | None:
    """Open log, right convention: a last point on a region's boundary takes the label of
    where the robot goes next, which the log does not say."""
    if trace.ending != "open" or trace.convention != "right" or not regions:
        return None
    shapes = [shapely.Polygon(p) for p in regions.values()]
    last = pieces.positions[-1:]
    on_boundary = (
        region_membership(shapes, last, closed=True)[0]
        & ~region_membership(shapes, last, closed=False)[0]
    )
    if not on_boundary.any():
        return None
    unknown = np.zeros_like(pieces.labels)
    unknown[-1] = on_boundary
    return unknown


def _piece_ending(trace: TraceInput, pieces: Pieces) -> PieceEnding:
    if trace.ending == "open":
        return "open"
    if pieces.loop_start is not None:
        return pieces.loop_start
    return "stay"


def _clock(trace: TraceInput) -> Clock:
    """The log's stamps of the verifier's times (from its first sample), and where messages
    count from."""
    return Clock(float(trace.times[0]), trace.start)


def _sample_cells(
    trace: TraceInput, times: FloatArray, atoms: Callable[[str], Value]
) -> tuple[Callable[[str], Value], int, PieceEnding, Timing]:
    """The samples (at ``times``, from the first) as a dense-time signal: sample i's bounds
    hold from the middle of the gap before it to the middle of the gap after it; at a middle
    instant both neighbours' bounds hold (the robot is within each one's radius then), so
    their intersection is taken.  A loop's last sample is the wrap back to its first."""
    n = len(times)
    middles = (times[:-1] + times[1:]) / 2.0
    loop = trace.loop_start if trace.ending == "loop" else None
    # instants: T_0, the middles, T_last; a loop's first sample's time is an instant too (the
    # loop returns to it), and its last sample is no instant (the wrap).
    instants = [float(times[0])]
    owners: list[tuple[int, int]] = [(0, 0)]  # the samples whose bounds hold at the instant
    stretch: list[int] = []  # the sample of the open stretch after each instant
    loop_instant = 0
    for i in range(1, n):
        stretch.append(i - 1)
        instants.append(float(middles[i - 1]))
        owners.append((i - 1, i))
        if loop is not None and i == loop:
            stretch.append(i)
            instants.append(float(times[i]))
            owners.append((i, i))
            loop_instant = len(instants) - 1
    if loop is not None:
        stretch.append(n - 1)  # up to the wrap
    elif n > 1:  # (a single sample is one instant)
        stretch.append(n - 1)
        instants.append(float(times[-1]))
        owners.append((n - 1, n - 1))
    first = np.array([o[0] for o in owners])
    second = np.array([o[1] for o in owners])
    stretch_of = np.array(stretch, dtype=np.int64)
    size = len(instants) + len(stretch)
    starts = np.empty(size)
    starts[0::2] = instants
    starts[1::2] = np.asarray(instants)[: len(stretch)]

    def cells(name: str) -> Value:
        lo, hi = atoms(name)
        out_lo, out_hi = np.empty(size), np.empty(size)
        out_lo[0::2] = np.maximum(lo[first], lo[second])
        out_hi[0::2] = np.minimum(hi[first], hi[second])
        out_lo[1::2], out_hi[1::2] = lo[stretch_of], hi[stretch_of]
        return out_lo, out_hi

    if loop is not None:
        ending: PieceEnding = 2 * loop_instant
    else:
        ending = "stay" if trace.ending == "stay" else "open"
    return cells, size, ending, Timing(starts, float(times[-1]))


def _prefix_end(starts: FloatArray, span: float) -> int | None:
    """How many pieces (``starts``: from the first sample, 0) cover ``[0, span]`` and end on an
    instant after it (None: the trace is not longer than that)."""
    if not math.isfinite(span):
        return None
    # pieces come in pairs (an instant and the stretch after it, with one start): an even count
    # ends on a stretch, closed by the instant at ``index``; an odd one is the whole trace
    index = int(np.searchsorted(starts, span, side="right"))
    if index % 2 or index >= len(starts):
        return None
    return index + 1


def _with_time_robustness(
    report: ConjunctReport,
    conjunct: Formula,
    outcome_of: Callable[[Formula], Outcome],
    truth: Semantics,
    line: Timeline,
    duration: float,
) -> ConjunctReport:
    """``report`` with the conjunct's time robustness and, for a bounded one, its progress."""
    if not bounded_operators(conjunct):
        return report
    slack = time_robustness(conjunct, report.outcome, outcome_of, horizon(conjunct, duration))
    first_broken = None
    if isinstance(conjunct, Globally):
        broken = np.flatnonzero(truth(conjunct.arg)[1][: line.size] < 0)
        if len(broken):
            first_broken = float(line.starts[int(broken[0])])
    first_done = None
    if isinstance(conjunct, BoundedEventually) and report.outcome == "satisfied":
        first_done = _first_done(truth.dense(), conjunct.arg, conjunct.interval.low)
    progress = timed_progress(
        conjunct, report.outcome, slack, first_broken, first_done=first_done, clock=line.clock
    )
    return dataclasses.replace(
        report, time_robustness=slack, progress=progress if progress else report.progress
    )


def _first_done(dense: DenseSemantics, goal: Formula, low: float) -> float | None:
    """When ``goal`` first holds at or after ``low`` (a deadline's goal done): an instant of its
    signal, or the start of an open stretch reaching past ``low`` (from the signal, not the
    pieces: a goal with bounds of its own may begin to hold inside a piece); None: not within
    the trace."""
    signal = dense.signal(goal)
    times, domain = signal.times, dense.domain
    ends = np.append(times[1:], np.inf if domain.loop_time is None else domain.end)
    held = signal.lo > 0
    reaching = np.empty(2 * len(times), dtype=bool)
    reaching[0::2] = held[0::2] & (times >= low)
    reaching[1::2] = held[1::2] & (ends > low)
    if not reaching.any():
        return None
    return max(float(times[int(np.argmax(reaching)) // 2]), low)


def _timed_violations(
    conjuncts: list[Formula],
    reports: list[ConjunctReport],
    found: list[Violation],
    truth: Semantics,
    trace: TraceInput,
    times: FloatArray,
    line: Timeline,
) -> list[Violation]:
    """The violations of conjuncts with time bounds, in dense time: for ``G x``, each maximal
    stretch of instants where ``x`` fails (exact ends), where it starts; for the others, their
    progress (``times``: the samples', from the first)."""
    timed = {
        to_text(c): (c, r)
        for c, r in zip(conjuncts, reports, strict=True)
        if bounded_operators(c) and r.outcome == "violated"
    }
    if not timed:
        return found
    kept = [v for v in found if v.conjunct not in timed]
    for text, (conjunct, report) in timed.items():
        if not isinstance(conjunct, Globally):
            kept.append(
                Counterexample(
                    conjunct=text, time=None, position=None, message=f"`{text}`: {report.progress}"
                )
            )
            continue
        signal = truth.dense().signal(conjunct.arg)
        stretches = _failing_stretches(signal.times, signal.hi, truth.dense().domain)
        for start, end in stretches:
            x, y = _position(line, times, trace.points, start)
            clock = line.clock
            when = (
                f"at {clock.at(start)}"
                if end == start
                else f"from {clock.at(start)} to {clock.at(end)}"
            )
            kept.append(
                Counterexample(
                    conjunct=text,
                    time=clock.stamp(start),
                    position=(x, y),
                    message=f"`{to_text(conjunct.arg)}` fails {when}, starting at "
                    f"({x:.4g}, {y:.4g}), while `{text}` must hold",
                )
            )
    return kept


def _position(
    line: Timeline, times: FloatArray, points: FloatArray, time: float
) -> tuple[float, float]:
    """Where the robot is at ``time``: the piece's own position where a piece starts then (a
    sample or a crossing, as every other message places it), else between the samples
    (``points`` at ``times``; every time from the first sample)."""
    k = int(np.searchsorted(line.starts, time))
    if k < line.size and line.starts[k] == time:
        x, y = line.positions[k].tolist()
        return float(x), float(y)
    return (
        float(np.interp(time, times, points[:, 0])),
        float(np.interp(time, times, points[:, 1])),
    )


def _failing_stretches(
    times: FloatArray, hi: FloatArray, domain: Domain
) -> list[tuple[float, float]]:
    """Maximal stretches ``[start, end]`` of a signal's positions where ``hi < 0``: a loop's
    last open position runs to the wrap; a stay's or an open log's, its tail, is left out (it
    is not part of the trace)."""
    positions = 2 * len(times) - (1 if domain.loop_time is None else 0)
    bad = hi[:positions] < 0
    stretches: list[tuple[float, float]] = []
    for first, last in runs(bad):
        start = float(times[first // 2])
        # an instant ends where it is; an open stretch at the next instant
        end = (
            float(times[last // 2])
            if last % 2 == 0
            else float(times[last // 2 + 1] if last // 2 + 1 < len(times) else domain.end)
        )
        stretches.append((start, end))
    return stretches


def _free_space(trace: TraceInput) -> shapely.Geometry | None:
    from tlmpc.verify.clearance import free_space

    free: shapely.Geometry | None = free_space(trace)
    return free


def _segments(points: FloatArray) -> npt.NDArray[np.object_]:
    if len(points) == 1:
        return np.asarray(shapely.points(points))
    return np.asarray(shapely.linestrings(np.stack([points[:-1], points[1:]], axis=1)))


def _body_contacts(
    trace: TraceInput, free: shapely.Geometry, distances: FloatArray
) -> list[Violation]:
    """Where the body (a disc of ``trace.radius`` around the point) first meets an obstacle
    of ``free`` (the trace's free space), given each segment's ``distances`` to its boundary."""
    assert trace.boundary_polygon is not None
    size = float(np.ptp(trace.boundary_polygon, axis=0).max())
    touching = np.flatnonzero(distances < trace.radius - 1e-9 * size)
    if not len(touching):
        return []
    index = int(touching[0])
    points, times, clock = trace.points, since_first(trace.times), _clock(trace)
    segment = points[index : index + 2]
    # where the segment first comes within the radius: its first point outside the free space
    # shrunk by the radius (a fine polygon of it; the sample nearest the wall if none is found)
    inner = free.buffer(-trace.radius, quad_segs=64)
    line = shapely.LineString(segment) if len(segment) == 2 else shapely.Point(segment[0])
    near = shapely.get_coordinates(shapely.difference(line, inner))
    if len(near) and len(segment) == 2:
        along = np.linalg.norm(near - segment[0], axis=1)
        first = near[int(np.argmin(along))]
        length = float(np.linalg.norm(segment[1] - segment[0]))
        fraction = float(np.min(along)) / length if length > 0.0 else 0.0
        time = float(times[index] + fraction * (times[index + 1] - times[index]))
    else:
        offsets = np.asarray(
            shapely.distance(free.boundary, shapely.points(segment)), dtype=np.float64
        )
        first = segment[int(np.argmin(offsets))]
        time = float(times[min(index + int(np.argmin(offsets)), len(points) - 1)])
    x, y = float(first[0]), float(first[1])
    return [
        Counterexample(
            conjunct="workspace",
            time=clock.stamp(time),
            position=(x, y),
            message=f"the robot's body (radius {trace.radius:g}) touches an obstacle from "
            f"{clock.at(time)} at ({x:.4g}, {y:.4g}): the path passes "
            f"{float(distances[index]):.4g} from it",
        )
    ]


def _distances(shape: Any, others: Any) -> FloatArray:
    """GEOS's distances from ``shape`` to each of ``others``.  A segment a hair long (3.6e-305)
    has a squared length that underflows to 0, and GEOS divides by it (a projection beyond
    the segment's end, or 0 / 0 beside a collinear edge) on its way to the right distance, the
    one to the segment's end or 0; numpy's flags raised on the way are no warning for the
    caller."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(shapely.distance(shape, others), dtype=np.float64)


def workspace_violations(trace: TraceInput) -> tuple[list[Violation], float | None]:
    """Every excursion out of the workspace or into a hole, and the workspace robustness.

    The robustness is the distance from the whole piecewise-linear path to the free space's
    boundary when it stays inside, else minus the deepest excursion point found.
    """
    free = _free_space(trace)
    if free is None:
        return [], None
    points = trace.points
    segments = _segments(points)
    inside = np.asarray(shapely.covers(free, segments), dtype=bool)
    if inside.all():
        distances = _distances(free.boundary, segments)
        clearance = float(np.min(distances))
        if trace.radius > 0.0:
            return _body_contacts(trace, free, distances), clearance - trace.radius
        return [], clearance
    found: list[Violation] = []
    depth = 0.0
    previous_bad = False
    times, clock = since_first(trace.times), _clock(trace)
    for index in range(len(segments)):
        if inside[index]:
            previous_bad = False
            continue
        outside = shapely.difference(segments[index], free) if len(points) > 1 else segments[index]
        coords = (
            shapely.get_coordinates(outside)
            if not shapely.is_empty(outside)
            else points[index : index + 1]
        )
        if len(points) > 1:
            middles = (points[index] + points[index + 1]) / 2.0
            probes = np.vstack([coords, middles[None, :]])
            outside_probes = probes[~shapely.covers(free, shapely.points(probes))]
            if len(outside_probes):
                depth = max(depth, float(np.max(_distances(free, shapely.points(outside_probes)))))
        if previous_bad:
            continue
        previous_bad = True
        start = points[index]
        along = np.linalg.norm(coords - start, axis=1)
        entry = coords[int(np.argmin(along))]
        if len(points) > 1:
            length = float(np.linalg.norm(points[index + 1] - start))
            fraction = float(np.linalg.norm(entry - start) / length) if length > 0 else 0.0
            time = float(times[index] + fraction * (times[index + 1] - times[index]))
        else:
            time = 0.0
        in_hole = any(
            shapely.Polygon(h).intersects(segments[index])
            for h in (*trace.holes, *(h for _, holes in trace.components for h in holes))
        )
        where = "entered a hole (an obstacle)" if in_hole else "left the workspace"
        x, y = float(entry[0]), float(entry[1])
        found.append(
            Counterexample(
                conjunct="workspace",
                time=clock.stamp(time),
                position=(x, y),
                message=f"the trajectory {where} at {clock.at(time)} at ({x:.4g}, {y:.4g})",
            )
        )
    if trace.radius > 0.0:
        # the body may meet an obstacle where the point stays inside, before it leaves
        distances = np.full(len(segments), np.inf)
        distances[inside] = shapely.distance(free.boundary, segments[inside])
        found.extend(_body_contacts(trace, free, distances))
        found.sort(key=lambda v: math.inf if v.time is None else v.time)
    return found, -depth


def certify(trace: TraceInput, regions: dict[str, FloatArray], outcome: Outcome) -> Certificate:
    """Check the speed assumption, then bound the robustness of every motion it allows."""
    stamps, points = trace.times, trace.points
    gaps = np.diff(stamps)
    max_gap = float(gaps.max()) if len(gaps) else 0.0
    speeds = np.linalg.norm(np.diff(points, axis=0), axis=1) / gaps if len(gaps) else np.zeros(0)
    observed = float(speeds.max()) if len(speeds) else 0.0
    speed = trace.max_speed

    def refuse(reason: str, bound: float | None = None) -> Certificate:
        return Certificate(
            certified=False,
            max_speed=speed,
            observed_speed=observed,
            max_gap=max_gap,
            bound=bound,
            margin=None,
            reason=reason,
        )

    if speed is None:
        return refuse("no max_speed is known, so nothing bounds the motion between samples")
    # on the stamps as logged: the check allows for their rounding
    excess = speed_excess(stamps, points, speed)
    times = since_first(stamps)
    if excess.any():
        index = int(np.argmax(np.where(excess > 0.0, speeds, -np.inf)))
        clock = _clock(trace)
        begin, end = clock.at(float(times[index])), clock.at(float(times[index + 1]))
        return refuse(
            f"the log moves at {float(speeds[index]):.4g} m/s between {begin} and {end}, "
            f"faster than max_speed {speed:.4g}: the "
            "certificate's assumption does not hold"
        )
    radii = tube_radii(times, speed)
    bound = float(radii.max())
    if outcome == "inconclusive":
        return refuse("an inconclusive verdict has nothing to certify", bound)
    atoms = tube_atoms(regions, points, radii)
    if bounded_operators(trace.formula):
        cells, size, ending, timing = _sample_cells(trace, times, atoms)
        tube = Semantics(cells, size, ending, timing=timing)
    else:
        samples: PieceEnding = "open"
        if trace.ending == "loop":
            samples = trace.loop_start or 0
        elif trace.ending == "stay":
            samples = len(times) - 1
        tube = Semantics(atoms, len(times), samples)
    lo, hi = tube.at_start(trace.formula)
    margin = lo if outcome == "satisfied" else -hi
    certified = margin > 0
    if certified:
        reason = (
            f"every motion at speed <= {speed:.4g} through these samples "
            f"{'satisfies' if outcome == 'satisfied' else 'violates'} the task "
            f"(margin {margin:.4g})"
        )
    else:
        reason = (
            f"a motion at speed <= {speed:.4g} through these samples may stray up to "
            f"{bound:.4g} from them, more than the task's robustness allows; sample more densely"
        )
    return Certificate(
        certified=certified,
        max_speed=speed,
        observed_speed=observed,
        max_gap=max_gap,
        bound=bound,
        margin=margin,
        reason=reason,
    )


@dataclasses.dataclass(frozen=True, slots=True)
class _Truth:
    """The trace cut into pieces at the crossings of the regions its task mentions, and the
    exact truth of formulas on them; every time from the first sample (``times``: the
    samples')."""

    times: FloatArray
    pieces: Pieces
    regions: dict[str, FloatArray]
    names: list[str]
    unknown: BoolArray | None
    size: int
    ending: PieceEnding
    is_point: BoolArray | None
    timing: Timing
    truth: Semantics

    prefixes: Prefixes

    def outcome_function(self) -> Callable[[Formula], Outcome]:
        """The verdict of a formula at the trace's start (one with finite bounds only is
        decided on the prefix its bounds reach)."""
        times, truth, prefixes = self.pieces.times, self.truth, self.prefixes

        def outcome_of(formula: Formula) -> Outcome:
            # A formula whose operators all have finite bounds is decided at t=0 by the trace
            # up to its reach: the searches for time robustness evaluate only that prefix.
            cut = _prefix_end(times, reach(formula))
            if cut is None:
                with truth.scratch():  # (the searches ask for many tightened variants)
                    return _outcome(*truth.at_start(formula))
            return prefixes.outcome(formula, cut)

        return outcome_of


def _truth_of(trace: TraceInput) -> _Truth:
    # Only the regions the task mentions can change its truth (no Next: the semantics is
    # stutter-invariant), so crossings of other regions are not split at.
    mentioned = trace.formula.props().union(*(a.props() for a in trace.assumptions))
    regions = {n: p for n, p in trace.regions.items() if n in mentioned}
    names = list(regions)
    loop_start = trace.loop_start if trace.ending == "loop" else None
    # every time from the first sample: bounds are decided on exact differences of stamps
    samples = since_first(trace.times)
    signals = counted_from(trace.signals, float(trace.times[0]))
    times, points, loop_sample = samples, trace.points, loop_start
    if signals:
        # a sample at every signal change: the run is cut there as at a region crossing
        times, points, moved = with_cuts(times, points, change_times(signals))
        loop_sample = None if loop_start is None else int(moved[loop_start])
    pieces = build_pieces(times, points, loop_sample, regions, trace.convention)
    unknown = _last_point_unknown(trace, pieces, regions)
    pieces, unknown, names = _with_signals(trace, signals, pieces, unknown, names, mentioned)
    size = len(pieces.is_point)
    ending = _piece_ending(trace, pieces)
    is_point = pieces.is_point if trace.convention == "closed" else None
    timing = Timing(pieces.times, float(samples[-1]))
    truth = Semantics(
        truth_atoms(pieces.labels, names, unknown),
        size,
        ending,
        is_point=is_point,
        timing=timing,
    )
    prefixes = Prefixes(truth_atoms(pieces.labels, names, unknown), pieces.times, is_point)
    return _Truth(
        samples, pieces, regions, names, unknown, size, ending, is_point, timing, truth, prefixes
    )


@dataclasses.dataclass(frozen=True, slots=True)
class BoundSlack:
    """One time bound of a task: the operator's text and by how many seconds it held (> 0)
    or failed (< 0), the other bounds kept (``inf``/``-inf``: any amount; None: under
    ``<->``, no direction)."""

    bound: str
    slack: float | None
    #: For a deadline asked about (see :func:`bound_slacks`) of a satisfied task: the time
    #: the trace meets it at, the earliest far end of its window that still holds (None:
    #: not asked, or not found; then ``T - slack`` says it, to the slack's precision).
    time: float | None = None


@contextlib.contextmanager
def _loop_limit(trace: TraceInput) -> Iterator[None]:
    """Refuse (V040) a task whose windows would unroll the trace's loop past
    :data:`~tlmpc.verify.dense.MAX_UNROLLED` pieces."""
    try:
        yield
    except UnrollTooLong as exc:
        raise UsageError(
            error(
                "V040",
                f"{exc}: the loop is too short for the length of the trace before it",
                hint="declare a longer loop (--loop-from earlier), or read the log's end as a "
                "stay (--assume-stay) or open",
                file=trace.source,
            )
        ) from None


def bound_slacks(
    trace: TraceInput, deadlines: Collection[int] = ()
) -> tuple[Outcome, tuple[BoundSlack, ...]]:
    """The task's verdict on ``trace`` and the slack of each of its bounded operators
    (pre-order): the time robustness of the task with that one bound moved; for those whose
    index is in ``deadlines`` (each an ``F[0,T]`` or ``U[0,T]`` occurring only positively)
    also the time the trace meets it at, when the task is satisfied.

    Raises:
        UsageError: V040, a window would unroll the trace's loop too far."""
    with _loop_limit(trace):
        return _bound_slacks(trace, deadlines)


def _bound_slacks(
    trace: TraceInput, deadlines: Collection[int]
) -> tuple[Outcome, tuple[BoundSlack, ...]]:
    found = _truth_of(trace)
    outcome_of = found.outcome_function()
    outcome = _outcome(*found.truth.at_start(trace.formula))
    duration = float(found.times[-1])
    span = horizon(trace.formula, duration)
    slacks = []
    for index, node in enumerate(bounded_operators(trace.formula)):
        time = None
        if (
            index in deadlines
            and outcome == "satisfied"
            and isinstance(node, BoundedEventually | BoundedUntil)
        ):
            time = tightest_deadline(trace.formula, node, outcome_of, duration)
        slacks.append(
            BoundSlack(
                bound=to_text(node),
                slack=time_robustness(trace.formula, outcome, outcome_of, span, only=node),
                time=time,
            )
        )
    return outcome, tuple(slacks)


def verify_trace(trace: TraceInput) -> Verdict:
    """Check ``trace`` against its task under its boundary convention and ending.

    Raises:
        UsageError: V040, a window would unroll the trace's loop too far."""
    with _loop_limit(trace):
        return _verify_trace(trace)


def _verify_trace(trace: TraceInput) -> Verdict:
    found = _truth_of(trace)
    pieces, regions, names, unknown = found.pieces, found.regions, found.names, found.unknown
    size, ending, is_point, timing = found.size, found.ending, found.is_point, found.timing
    truth = found.truth
    loop_start = trace.loop_start if trace.ending == "loop" else None
    task_outcome = _outcome(*truth.at_start(trace.formula))
    conjuncts = _conjuncts(trace.formula)
    outcomes = [_outcome(*truth.at_start(c)) for c in conjuncts]
    ends = np.append(pieces.times[1:], pieces.times[-1])
    if loop_start is not None and size:
        ends[-1] = found.times[-1]
    line = Timeline(
        starts=pieces.times,
        ends=ends,
        positions=pieces.positions,
        labels=pieces.labels,
        names=names,
        clock=_clock(trace),
        signals=frozenset(trace.sensors) | frozenset(trace.actions),
    )
    reports, violations = conjunct_reports(conjuncts, outcomes, truth, line)

    outcome_of = found.outcome_function()
    reactive: AssumeGuarantee | None = None
    if trace.reactive:
        reactive = assume_guarantee(
            trace.assumptions,
            conjuncts,
            task_outcome,
            lambda formula: _outcome(*truth.at_start(formula)),
            found.prefixes,
            ending,
        )

    duration = float(found.times[-1])
    reports = [
        _with_time_robustness(report, conjunct, outcome_of, truth, line, duration)
        for report, conjunct in zip(reports, conjuncts, strict=True)
    ]
    violations = _timed_violations(conjuncts, reports, violations, truth, trace, found.times, line)
    task_slack = conjunction_robustness(
        [
            (c, report.outcome, report.time_robustness)
            for c, report in zip(conjuncts, reports, strict=True)
        ],
        task_outcome,
    )
    excursions, workspace_rho = workspace_violations(trace)
    judged = task_outcome if reactive is None else reactive.outcome
    outcome: Outcome = "violated" if excursions else judged
    # Robustness on the same pieces and recursion as the truth: the signs agree.
    space = Semantics(
        _space_atoms(regions, pieces, unknown, names),
        size,
        ending,
        is_point=is_point,
        timing=timing,
    )
    lo, hi = space.at_start(trace.formula)
    rho = lo if lo > 0 else hi if hi < 0 else 0.0
    if excursions and workspace_rho is not None:
        rho = min(rho, workspace_rho)
    if trace.reactive:
        certificate = _reactive_certificate(trace)
    else:
        certificate = certify(trace, regions, task_outcome)
    if excursions and certificate.certified:
        certificate = Certificate(
            certified=task_outcome == "violated",
            max_speed=certificate.max_speed,
            observed_speed=certificate.observed_speed,
            max_gap=certificate.max_gap,
            bound=certificate.bound,
            margin=certificate.margin,
            reason=certificate.reason + " (the task alone; the workspace check fails as well)",
        )
    merged = merge_pieces(pieces, trace.convention)
    return Verdict(
        outcome=outcome,
        formula=to_text(trace.formula),
        convention=trace.convention,
        ending=trace.ending,
        robustness=rho,
        time_robustness=task_slack,
        certificate=certificate,
        pieces=len(merged.is_point),
        conjuncts=tuple(reports),
        violations=tuple(excursions + violations),
        stats={
            "samples": len(trace.times),
            "raw_pieces": size,
            "start_time": float(trace.times[0]),
            "duration": float(trace.times[-1] - trace.times[0]),
        },
        reactive=reactive,
    )


def _reactive_certificate(trace: TraceInput) -> Certificate:
    """No certificate for a reactive run: it bounds the robot's motion between samples, and
    nothing bounds the sensors' values between theirs."""
    gaps = np.diff(trace.times)
    speeds = np.linalg.norm(np.diff(trace.points, axis=0), axis=1) / gaps if len(gaps) else gaps
    return Certificate(
        certified=False,
        max_speed=trace.max_speed,
        observed_speed=float(speeds.max()) if len(speeds) else 0.0,
        max_gap=float(gaps.max()) if len(gaps) else 0.0,
        bound=None,
        margin=None,
        reason="not computed for a reactive run (the certificate bounds the robot's motion "
        "between samples, not the sensors' values)",
    )


def _with_signals(
    trace: TraceInput,
    signals: Mapping[str, Signal],
    pieces: Pieces,
    unknown: BoolArray | None,
    names: list[str],
    mentioned: Set[str],
) -> tuple[Pieces, BoolArray | None, list[str]]:
    """The pieces' labels with a column for each sensor and action the formulas mention: its
    value at the piece's first instant (unknown before the signal's first sample, and
    throughout for an action the log does not carry); ``signals`` are the trace's, timed as
    the pieces are."""
    signal_names = [n for n in (*trace.sensors, *trace.actions) if n in mentioned]
    if not signal_names:
        return pieces, unknown, names
    values, unknown_signals = signal_labels(signals, signal_names, pieces.times)
    labels = np.hstack([pieces.labels, values])
    if unknown is None and not unknown_signals.any():
        combined = None
    else:
        regions_unknown = np.zeros_like(pieces.labels) if unknown is None else unknown
        combined = np.hstack([regions_unknown, unknown_signals])
    return dataclasses.replace(pieces, labels=labels), combined, [*names, *signal_names]


def _space_atoms(
    regions: dict[str, FloatArray], pieces: Pieces, unknown: BoolArray | None, names: list[str]
) -> Callable[[str], Value]:
    """Robustness atoms: signed distances for regions; for a sensor or an action, +inf while
    it holds and -inf while it does not (no motion changes it), 0 where it is unknown."""
    distances = piece_atoms(regions, pieces.positions, pieces.labels, unknown)

    def atom(name: str) -> Value:
        if name in regions:
            return distances(name)
        column = names.index(name)
        value = np.where(pieces.labels[:, column], np.inf, -np.inf)
        if unknown is not None:
            value = np.where(unknown[:, column], 0.0, value)
        return value, value

    return atom


def _number(value: float | None) -> float | str | None:
    if value is None or math.isfinite(value):
        return value
    return "inf" if value > 0 else "-inf"


def _example(example: Counterexample | None) -> dict[str, Any] | None:
    if example is None:
        return None
    return {
        "conjunct": example.conjunct,
        "time": example.time,
        "position": list(example.position) if example.position else None,
        "message": example.message,
    }


def _report(report: ConjunctReport) -> dict[str, Any]:
    return {
        "conjunct": report.conjunct,
        "verdict": report.outcome,
        "progress": report.progress,
        "visits": report.visits,
        "last_visit": report.last_visit,
        "longest_gap": report.longest_gap,
        "time_robustness": _number(report.time_robustness),
    }


def _part(part: PartVerdict | None, start: float) -> dict[str, Any] | None:
    if part is None:
        return None
    return {
        "part": part.part,
        "verdict": part.outcome,
        "broken_at": None if part.broken is None else start + part.broken,
        "elapsed": part.broken,
    }


def reactive_to_json(judged: AssumeGuarantee, start: float) -> dict[str, Any]:
    """The ``reactive`` object of ``tlmpc.verdict/1``: blame, both times, every part
    (``start``: the stamp of the log's first sample)."""
    return {
        "verdict": judged.outcome,
        "blame": judged.blame,
        "vacuous": judged.blame == "environment",
        "environment": _part(judged.environment, start),
        "robot": _part(judged.robot, start),
        "assumptions": [_part(p, start) for p in judged.assumptions],
        "guarantees": [_part(p, start) for p in judged.guarantees],
    }


def verdict_to_json(verdict: Verdict) -> dict[str, Any]:
    """``tlmpc.verdict/1``."""
    certificate = verdict.certificate
    extra: dict[str, Any] = {}
    if verdict.reactive is not None:
        extra["reactive"] = reactive_to_json(verdict.reactive, float(verdict.stats["start_time"]))
    return {
        "format": "tlmpc.verdict/1",
        "verdict": verdict.outcome,
        "satisfied": verdict.satisfied,
        "formula": verdict.formula,
        "boundary": verdict.convention,
        "ending": verdict.ending,
        "robustness": _number(verdict.robustness),
        "time_robustness": _number(verdict.time_robustness),
        "certificate": {
            "certified": certificate.certified,
            "bound": certificate.bound,
            "max_gap": certificate.max_gap,
            "max_speed": certificate.max_speed,
            "observed_speed": certificate.observed_speed,
            "margin": _number(certificate.margin),
            "reason": certificate.reason,
        },
        "pieces": verdict.pieces,
        "conjuncts": [_report(r) for r in verdict.conjuncts],
        "violations": [_example(v) for v in verdict.violations],
        "counterexample": _example(verdict.counterexample),
        "workspace_violation": _example(verdict.workspace_violation),
        "stats": dict(verdict.stats),
        **extra,
    }
