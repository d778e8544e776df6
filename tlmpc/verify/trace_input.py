"""Reading traces to verify: ``trace.json`` documents and CSV logs, with V-coded diagnostics.

Independent of the compiler's stages: only the LTL parser, the mission loader (for CSV
traces) and shared error types are used.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from tlmpc.errors import UsageError, error
from tlmpc.ltl.ast import Formula
from tlmpc.ltl.parser import parse_ltl

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True, slots=True, kw_only=True)
class TraceInput:
    """A validated trajectory and the specification to check it against."""

    times: FloatArray = field(compare=False)
    points: FloatArray = field(compare=False)
    loop_start: int | None
    formula: Formula
    regions: Mapping[str, FloatArray]
    boundary_polygon: FloatArray | None = field(compare=False)
    holes: tuple[FloatArray, ...] = ()
    convention: str = "right"
    max_speed: float | None = None
    source: str | None = None


def _fail(
    code: str, message: str, file: str | None, hint: str | None = None, line: int | None = None
) -> UsageError:
    return UsageError(error(code, message, hint=hint, file=file, line=line))


def _polygon(value: Any, what: str, file: str | None) -> FloatArray:
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise _fail("V004", f"{what} is not a list of [x, y] points", file) from None
    if array.ndim != 2 or array.shape[1] != 2 or array.shape[0] < 3:
        raise _fail("V004", f"{what} is not a polygon (at least 3 [x, y] points)", file)
    if not np.all(np.isfinite(array)):
        raise _fail("V004", f"{what} has a non-finite coordinate", file)
    return array


def _samples(rows: Any, file: str | None, lines: list[int] | None = None) -> FloatArray:
    try:
        array = np.asarray(rows, dtype=np.float64)
    except (TypeError, ValueError):
        raise _fail("V002", "points must be rows of three numbers [t, x, y]", file) from None
    if array.ndim != 2 or array.shape[1] != 3:
        raise _fail("V002", "points must be rows of three numbers [t, x, y]", file)
    if len(array) == 0:
        raise _fail("V002", "the trace has no samples", file, hint="record at least one sample")
    bad = np.flatnonzero(~np.all(np.isfinite(array), axis=1))
    if len(bad):
        row = int(bad[0])
        raise _fail(
            "V003",
            f"sample {row} has a non-finite value (NaN or infinity)",
            file,
            line=lines[row] if lines else None,
        )
    order = np.flatnonzero(np.diff(array[:, 0]) <= 0)
    if len(order):
        row = int(order[0]) + 1
        raise _fail(
            "V005",
            f"time does not increase at sample {row} "
            f"(t = {array[row - 1, 0]:g} then {array[row, 0]:g})",
            file,
            hint="samples must be sorted by strictly increasing time",
            line=lines[row] if lines else None,
        )
    return array


def _formula(text: Any, names: set[str], file: str | None) -> Formula:
    if not isinstance(text, str):
        raise _fail("V006", "the trace has no `ltl` task", file)
    from tlmpc.errors import InvalidInputError

    try:
        formula = parse_ltl(text, file=file)
    except InvalidInputError as exc:
        raise UsageError(exc.diagnostics) from None
    unknown = sorted(formula.props() - names)
    if unknown:
        raise _fail(
            "V007",
            f"the task names unknown regions: {', '.join(unknown)}",
            file,
            hint="every region in `ltl` must be defined under `regions`",
        )
    return formula


def from_document(
    document: Mapping[str, Any], *, file: str | None = None, convention: str | None = None
) -> TraceInput:
    """Validate a ``tlmpc.trace/1`` document."""
    fmt = document.get("format")
    if not isinstance(fmt, str) or not fmt.startswith("tlmpc.trace/"):
        raise _fail(
            "V001",
            f"not a tlmpc trace (format {fmt!r})",
            file,
            hint="pass a trace.json written by `tlmpc compile`, or a CSV with --mission",
        )
    regions_doc = document.get("regions")
    if not isinstance(regions_doc, dict):
        raise _fail("V004", "the trace has no `regions`", file)
    regions = {str(k): _polygon(v, f"region {k!r}", file) for k, v in regions_doc.items()}
    samples = _samples(document.get("points"), file)
    loop = document.get("loop_start")
    if loop is not None and (
        not isinstance(loop, int) or isinstance(loop, bool) or not 0 <= loop < len(samples)
    ):
        raise _fail("V008", f"loop_start {loop!r} is not a sample index", file)
    workspace = document.get("workspace") or {}
    boundary = workspace.get("boundary")
    holes = tuple(
        _polygon(h, f"hole {i}", file) for i, h in enumerate(workspace.get("holes") or [])
    )
    chosen = convention or document.get("boundary") or "right"
    if chosen not in ("right", "closed"):
        raise _fail(
            "V009", f"unknown boundary convention {chosen!r}", file, hint="use right or closed"
        )
    speed = document.get("max_speed")
    return TraceInput(
        times=samples[:, 0].copy(),
        points=samples[:, 1:].copy(),
        loop_start=loop,
        formula=_formula(document.get("ltl"), set(regions), file),
        regions=regions,
        boundary_polygon=_polygon(boundary, "workspace boundary", file) if boundary else None,
        holes=holes,
        convention=chosen,
        max_speed=float(speed) if isinstance(speed, int | float) and math.isfinite(speed) else None,
        source=file,
    )


def read_csv(path: Path, columns: Sequence[str] | None = None) -> tuple[FloatArray, list[int]]:
    """A CSV log's ``[t, x, y]`` rows (see :mod:`tlmpc.importers.logs`), with line numbers."""
    from tlmpc.importers.logs import read_csv_log

    log = read_csv_log(path, columns)
    lines = list(log.lines)
    return _samples(log.samples, str(path), lines), lines


def from_csv(
    path: Path,
    mission_path: Path | None,
    convention: str | None,
    *,
    topic: str | None = None,
    columns: Sequence[str] | None = None,
    transform: tuple[float, float, float] | None = None,
) -> TraceInput:
    """A logged trajectory (CSV or ROS bag) checked against a mission file's regions and task."""
    if mission_path is None:
        raise _fail(
            "V010", "a CSV trace needs --mission MISSION.yaml for its regions and task", str(path)
        )
    from tlmpc.errors import InvalidInputError
    from tlmpc.importers.logs import read_log
    from tlmpc.ltl.printer import to_text
    from tlmpc.mission.load import load_mission

    try:
        mission = load_mission(mission_path)
    except InvalidInputError as exc:
        raise UsageError(exc.diagnostics) from None
    log = read_log(path, topic=topic, columns=columns, transform=transform)
    samples = _samples(log.samples, str(path), list(log.lines) or None)
    document = {
        "format": "tlmpc.trace/1",
        "ltl": to_text(mission.formula),
        "regions": {r.name: [list(p) for p in r.polygon] for r in mission.regions},
        "workspace": {
            "boundary": [list(p) for p in mission.workspace.boundary],
            "holes": [[list(p) for p in h] for h in mission.workspace.holes],
        },
        "boundary": mission.options.boundary,
        "max_speed": mission.robot.max_speed,
        "points": samples.tolist(),
        "loop_start": None,
    }
    return from_document(document, file=str(path), convention=convention)
