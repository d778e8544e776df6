"""The verdict: truth (two- or three-valued), per-conjunct progress, every violation,
robustness that agrees with the verdict, and the certificate for the real robot."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt
import shapely

from tlmpc.ltl.ast import And, Formula
from tlmpc.ltl.printer import to_text
from tlmpc.verify.evaluate import UNKNOWN, IntervalEvaluator, Value, truth_atoms
from tlmpc.verify.model import (
    Certificate,
    ConjunctReport,
    Counterexample,
    Outcome,
    Verdict,
    Violation,
)
from tlmpc.verify.pieces import Pieces, build_pieces, merge_pieces, region_membership
from tlmpc.verify.progress import Timeline, conjunct_reports
from tlmpc.verify.robustness import (
    evaluate_with_ending,
    piece_atoms,
    tube_atoms,
    tube_radii,
)
from tlmpc.verify.trace_input import TraceInput

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

#: Relative slack on the speed check (rounding of time stamps and positions).
SPEED_SLACK = 1e-9


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


class _Truth:
    """Three-valued truth on the pieces, with the unknown future after an open log."""

    def __init__(
        self, trace: TraceInput, pieces: Pieces, names: list[str], unknown: BoolArray | None
    ) -> None:
        size = len(pieces.is_point)
        self.size = size
        is_point = pieces.is_point if trace.convention == "closed" else None
        atoms = truth_atoms(pieces.labels, names, unknown)
        if trace.ending == "open":

            def padded(name: str) -> Value:
                lo, hi = atoms(name)
                return np.append(lo, UNKNOWN[0]), np.append(hi, UNKNOWN[1])

            points = None if is_point is None else np.append(is_point, False)
            self.evaluator = IntervalEvaluator(padded, size + 1, size, points)
        else:
            loop = pieces.loop_start if pieces.loop_start is not None else size - 1
            self.evaluator = IntervalEvaluator(atoms, size, loop, is_point)

    def __call__(self, formula: Formula) -> Value:
        return self.evaluator(formula)

    def outcome(self, formula: Formula) -> Outcome:
        lo, hi = self.evaluator(formula)
        return _outcome(float(lo[0]), float(hi[0]))


def _free_space(trace: TraceInput) -> shapely.Geometry | None:
    from tlmpc.verify.clearance import free_space

    free: shapely.Geometry | None = free_space(trace)
    return free


def _segments(points: FloatArray) -> npt.NDArray[np.object_]:
    if len(points) == 1:
        return np.asarray(shapely.points(points))
    return np.asarray(shapely.linestrings(np.stack([points[:-1], points[1:]], axis=1)))


def _body_contacts(trace: TraceInput, distances: FloatArray) -> list[Violation]:
    """Where the body (a disc of ``trace.radius`` around the point) first meets an obstacle."""
    assert trace.boundary_polygon is not None
    size = float(np.ptp(trace.boundary_polygon, axis=0).max())
    touching = np.flatnonzero(distances < trace.radius - 1e-9 * size)
    if not len(touching):
        return []
    index = int(touching[0])
    points = trace.points
    segment = points[index : index + 2]
    free = _free_space(trace)
    assert free is not None
    offsets = np.asarray(shapely.distance(free.boundary, shapely.points(segment)), dtype=np.float64)
    closest = segment[int(np.argmin(offsets))]
    time = float(trace.times[min(index + int(np.argmin(offsets)), len(points) - 1)])
    x, y = float(closest[0]), float(closest[1])
    return [
        Counterexample(
            conjunct="workspace",
            time=time,
            position=(x, y),
            message=f"the robot's body (radius {trace.radius:g}) touches an obstacle near "
            f"t={time:.4g} s at ({x:.4g}, {y:.4g}): the path passes "
            f"{float(distances[index]):.4g} from it",
        )
    ]


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
        distances = np.asarray(shapely.distance(free.boundary, segments), dtype=np.float64)
        clearance = float(np.min(distances))
        if trace.radius > 0.0:
            return _body_contacts(trace, distances), clearance - trace.radius
        return [], clearance
    found: list[Violation] = []
    depth = 0.0
    previous_bad = False
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
                depth = max(
                    depth, float(np.max(shapely.distance(free, shapely.points(outside_probes))))
                )
        if previous_bad:
            continue
        previous_bad = True
        start = points[index]
        along = np.linalg.norm(coords - start, axis=1)
        entry = coords[int(np.argmin(along))]
        if len(points) > 1:
            length = float(np.linalg.norm(points[index + 1] - start))
            fraction = float(np.linalg.norm(entry - start) / length) if length > 0 else 0.0
            gap = trace.times[index + 1] - trace.times[index]
            time = float(trace.times[index] + fraction * gap)
        else:
            time = float(trace.times[0])
        in_hole = any(
            shapely.Polygon(h).intersects(segments[index])
            for h in (*trace.holes, *(h for _, holes in trace.components for h in holes))
        )
        where = "entered a hole (an obstacle)" if in_hole else "left the workspace"
        x, y = float(entry[0]), float(entry[1])
        found.append(
            Counterexample(
                conjunct="workspace",
                time=time,
                position=(x, y),
                message=f"the trajectory {where} at t={time:.4g} s at ({x:.4g}, {y:.4g})",
            )
        )
    return found, -depth


def certify(trace: TraceInput, regions: dict[str, FloatArray], outcome: Outcome) -> Certificate:
    """Check the speed assumption, then bound the robustness of every motion it allows."""
    times, points = trace.times, trace.points
    gaps = np.diff(times)
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
    if observed > speed * (1 + SPEED_SLACK):
        index = int(np.argmax(speeds))
        return refuse(
            f"the log moves at {observed:.4g} m/s between t={times[index]:.4g} s and "
            f"t={times[index + 1]:.4g} s, faster than max_speed {speed:.4g}: the "
            "certificate's assumption does not hold"
        )
    radii = tube_radii(times, speed)
    bound = float(radii.max())
    if outcome == "inconclusive":
        return refuse("an inconclusive verdict has nothing to certify", bound)
    loop = {"loop": trace.loop_start, "stay": len(times) - 1, "open": None}[trace.ending]
    lo, hi = evaluate_with_ending(
        trace.formula, tube_atoms(regions, points, radii), len(times), loop
    )
    margin = float(lo[0]) if outcome == "satisfied" else -float(hi[0])
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


def verify_trace(trace: TraceInput) -> Verdict:
    """Check ``trace`` against its task under its boundary convention and ending."""
    # Only the regions the task mentions can change its truth (no Next: the semantics is
    # stutter-invariant), so crossings of other regions are not split at.
    mentioned = trace.formula.props()
    regions = {n: p for n, p in trace.regions.items() if n in mentioned}
    names = list(regions)
    loop_start = trace.loop_start if trace.ending == "loop" else None
    pieces = build_pieces(trace.times, trace.points, loop_start, regions, trace.convention)
    unknown = _last_point_unknown(trace, pieces, regions)
    truth = _Truth(trace, pieces, names, unknown)
    task_outcome = truth.outcome(trace.formula)
    conjuncts = _conjuncts(trace.formula)
    outcomes = [truth.outcome(c) for c in conjuncts]
    size = len(pieces.is_point)
    ends = np.append(pieces.times[1:], pieces.times[-1])
    if loop_start is not None and size:
        ends[-1] = trace.times[-1]
    line = Timeline(
        starts=pieces.times,
        ends=ends,
        positions=pieces.positions,
        labels=pieces.labels,
        names=names,
    )
    reports, violations = conjunct_reports(conjuncts, outcomes, truth, line)
    excursions, workspace_rho = workspace_violations(trace)
    outcome: Outcome = "violated" if excursions else task_outcome
    # Robustness on the same pieces and recursion as the truth: the signs agree.
    is_point = pieces.is_point if trace.convention == "closed" else None
    loop = (
        None
        if trace.ending == "open"
        else (pieces.loop_start if pieces.loop_start is not None else size - 1)
    )
    lo, hi = evaluate_with_ending(
        trace.formula,
        piece_atoms(regions, pieces.positions, pieces.labels, unknown),
        size,
        loop,
        is_point,
    )
    rho = float(lo[0]) if lo[0] > 0 else float(hi[0]) if hi[0] < 0 else 0.0
    if excursions and workspace_rho is not None:
        rho = min(rho, workspace_rho)
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
        certificate=certificate,
        pieces=len(merged.is_point),
        conjuncts=tuple(reports),
        violations=tuple(excursions + violations),
        stats={"samples": len(trace.times), "raw_pieces": size},
    )


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
    }


def verdict_to_json(verdict: Verdict) -> dict[str, Any]:
    """``tlmpc.verdict/1``."""
    certificate = verdict.certificate
    return {
        "format": "tlmpc.verdict/1",
        "verdict": verdict.outcome,
        "satisfied": verdict.satisfied,
        "formula": verdict.formula,
        "boundary": verdict.convention,
        "ending": verdict.ending,
        "robustness": _number(verdict.robustness),
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
    }
