"""The verdict: continuous-time truth, counterexample, workspace violations, robustness."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
import shapely

from tlmpc.ltl.ast import And, Eventually, Formula, Globally, Not, Prop, Until
from tlmpc.ltl.printer import to_text
from tlmpc.verify.evaluate import LassoEvaluator
from tlmpc.verify.pieces import Pieces, build_pieces, merge_pieces
from tlmpc.verify.robustness import robustness
from tlmpc.verify.trace_input import TraceInput

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True, slots=True, kw_only=True)
class Counterexample:
    """Which part of the task fails, when and where, in words."""

    conjunct: str
    time: float | None
    position: tuple[float, float] | None
    message: str


@dataclass(frozen=True, slots=True, kw_only=True)
class Verdict:
    """The verifier's answer for one trace."""

    satisfied: bool
    formula: str
    convention: str
    robustness: float
    certified: bool
    certificate_bound: float | None
    max_gap: float
    pieces: int
    counterexample: Counterexample | None = None
    workspace_violation: Counterexample | None = None
    stats: Mapping[str, Any] = field(default_factory=dict)


def _conjuncts(formula: Formula) -> list[Formula]:
    return list(formula.args) if isinstance(formula, And) else [formula]


def _where(pieces: Pieces, k: int) -> tuple[float, tuple[float, float]]:
    x, y = pieces.positions[k].tolist()
    return float(pieces.times[k]), (float(x), float(y))


def _first(mask: npt.NDArray[np.bool_]) -> int | None:
    found = np.flatnonzero(mask)
    return int(found[0]) if len(found) else None


def _explain(
    conjunct: Formula, evaluator: LassoEvaluator, pieces: Pieces, names: list[str]
) -> Counterexample:
    text = to_text(conjunct)
    if isinstance(conjunct, Globally):
        bad = _first(~evaluator(conjunct.arg))
        if bad is not None:
            time, position = _where(pieces, bad)
            inside = [names[i] for i in np.flatnonzero(pieces.labels[bad])]
            forbidden = [
                n.arg.name
                for n in conjunct.arg.walk()
                if isinstance(n, Not) and isinstance(n.arg, Prop) and n.arg.name in inside
            ]
            if forbidden:
                message = (
                    f"entered {forbidden[0]} at t={time:.4g} s at "
                    f"({position[0]:.4g}, {position[1]:.4g}) while `{text}` must hold"
                )
            else:
                where = ", ".join(inside) if inside else "free space"
                message = (
                    f"`{to_text(conjunct.arg)}` stops holding at t={time:.4g} s at "
                    f"({position[0]:.4g}, {position[1]:.4g}) (in {where}) while "
                    f"`{text}` must hold"
                )
            return Counterexample(conjunct=text, time=time, position=position, message=message)
    if isinstance(conjunct, Eventually):
        return Counterexample(
            conjunct=text,
            time=None,
            position=None,
            message=f"`{to_text(conjunct.arg)}` never holds, so `{text}` fails",
        )
    if isinstance(conjunct, Until):
        left = evaluator(conjunct.left)
        right = evaluator(conjunct.right)
        if not right.any():
            return Counterexample(
                conjunct=text,
                time=None,
                position=None,
                message=f"`{to_text(conjunct.right)}` never holds, so `{text}` fails",
            )
        bad = _first(~left & ~right)
        if bad is not None:
            time, position = _where(pieces, bad)
            return Counterexample(
                conjunct=text,
                time=time,
                position=position,
                message=f"`{to_text(conjunct.left)}` stops holding at "
                f"t={time:.4g} s at ({position[0]:.4g}, {position[1]:.4g}) "
                f"before `{to_text(conjunct.right)}` holds",
            )
    return Counterexample(
        conjunct=text,
        time=None,
        position=None,
        message=f"`{text}` does not hold on this trajectory",
    )


def _workspace_violation(trace: TraceInput) -> Counterexample | None:
    if trace.boundary_polygon is None:
        return None
    free = shapely.Polygon(trace.boundary_polygon)
    if trace.holes:
        free = free.difference(shapely.union_all([shapely.Polygon(h) for h in trace.holes]))
    # Prepared: the bulk `covers` below then uses an indexed test per segment.
    shapely.prepare(free)
    points = trace.points
    if len(points) == 1:
        segments = shapely.points(points)
    else:
        segments = shapely.linestrings(np.stack([points[:-1], points[1:]], axis=1))
    inside = shapely.covers(free, segments)
    bad = _first(~np.asarray(inside))
    if bad is None:
        return None
    outside = shapely.difference(segments[bad], free) if len(points) > 1 else segments[bad]
    start = points[bad]
    entry = start
    if not shapely.is_empty(outside):
        coords = shapely.get_coordinates(outside)
        along = np.linalg.norm(coords - start, axis=1)
        entry = coords[int(np.argmin(along))]
    if len(points) > 1:
        length = np.linalg.norm(points[bad + 1] - start)
        fraction = float(np.linalg.norm(entry - start) / length) if length > 0 else 0.0
        time = float(trace.times[bad] + fraction * (trace.times[bad + 1] - trace.times[bad]))
    else:
        time = float(trace.times[0])
    in_hole = any(shapely.Polygon(h).intersects(segments[bad]) for h in trace.holes)
    where = "entered a hole (an obstacle)" if in_hole else "left the workspace"
    x, y = float(entry[0]), float(entry[1])
    return Counterexample(
        conjunct="workspace",
        time=time,
        position=(x, y),
        message=f"the trajectory {where} at t={time:.4g} s at ({x:.4g}, {y:.4g})",
    )


def verify_trace(trace: TraceInput) -> Verdict:
    """Check ``trace`` against its task under its boundary convention."""
    # Only the regions the task mentions can change its truth (no Next: the semantics is
    # stutter-invariant), so crossings of other regions are not split at; this keeps the label
    # matrix small on large maps.
    mentioned = trace.formula.props()
    regions = {n: p for n, p in trace.regions.items() if n in mentioned}
    names = list(regions)
    raw = build_pieces(trace.times, trace.points, trace.loop_start, regions, trace.convention)
    pieces = merge_pieces(raw, trace.convention)
    loop = pieces.loop_start if pieces.loop_start is not None else len(pieces.is_point) - 1
    evaluator = LassoEvaluator(
        pieces.labels, names, loop, pieces.is_point if trace.convention == "closed" else None
    )
    holds = bool(evaluator(trace.formula)[0])
    counterexample = None
    if not holds:
        failing = [c for c in _conjuncts(trace.formula) if not evaluator(c)[0]]
        counterexample = _explain(failing[0], evaluator, pieces, names)
    violation = _workspace_violation(trace)
    rho = robustness(trace.formula, trace.times, trace.points, trace.loop_start, regions)
    gaps = np.diff(trace.times)
    max_gap = float(gaps.max()) if len(gaps) else 0.0
    bound = None if trace.max_speed is None else trace.max_speed * max_gap
    satisfied = holds and violation is None
    certified = bool(satisfied and bound is not None and rho > bound)
    return Verdict(
        satisfied=satisfied,
        formula=to_text(trace.formula),
        convention=trace.convention,
        robustness=rho,
        certified=certified,
        certificate_bound=bound,
        max_gap=max_gap,
        pieces=len(pieces.is_point),
        counterexample=counterexample,
        workspace_violation=violation,
        stats={"samples": len(trace.times), "raw_pieces": len(raw.is_point)},
    )


def _example(example: Counterexample | None) -> dict[str, Any] | None:
    if example is None:
        return None
    return {
        "conjunct": example.conjunct,
        "time": example.time,
        "position": list(example.position) if example.position else None,
        "message": example.message,
    }


def verdict_to_json(verdict: Verdict) -> dict[str, Any]:
    """``tlmpc.verdict/1``."""
    rho = verdict.robustness
    return {
        "format": "tlmpc.verdict/1",
        "satisfied": verdict.satisfied,
        "formula": verdict.formula,
        "boundary": verdict.convention,
        "robustness": rho if math.isfinite(rho) else ("inf" if rho > 0 else "-inf"),
        "certificate": {
            "certified": verdict.certified,
            "bound": verdict.certificate_bound,
            "max_gap": verdict.max_gap,
        },
        "pieces": verdict.pieces,
        "counterexample": _example(verdict.counterexample),
        "workspace_violation": _example(verdict.workspace_violation),
        "stats": dict(verdict.stats),
    }
