"""Reading traces to verify: ``trace.json`` documents and CSV logs, with V-coded diagnostics.

Independent of the compiler's stages: only the LTL parser, the mission loader (for CSV
traces) and shared error types are used.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
import numpy.typing as npt

from tlmpc.base.errors import Diagnostic, UsageError, error
from tlmpc.io.json_places import json_path
from tlmpc.ltl.ast import Formula
from tlmpc.verify.model import Ending
from tlmpc.verify.samples import MAX_MAGNITUDE, CellPlace, SampleOrigin, check_samples
from tlmpc.verify.signals import Signal, signals_of_document

if TYPE_CHECKING:
    from tlmpc.mission.model import Mission

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
    #: further pieces of free space: each an outer boundary and its holes
    components: tuple[tuple[FloatArray, tuple[FloatArray, ...]], ...] = field(
        default=(), compare=False
    )
    convention: str = "right"
    ending: Ending = "open"
    max_speed: float | None = None
    source: str | None = None
    #: The robot's body radius: the body must stay off obstacles, not just the point.
    radius: float = 0.0
    #: When the log started, if before ``times[0]`` (a stretch of a longer log, as the live
    #: monitor checks): messages give times from here.
    origin: float | None = None
    #: A reactive run's sensors and actions (propositions whose values are in ``signals``)
    #: and the environment's assumptions; ``formula`` is then the robot's guarantee.
    sensors: tuple[str, ...] = ()
    actions: tuple[str, ...] = ()
    assumptions: tuple[Formula, ...] = ()
    signals: Mapping[str, Signal] = field(default_factory=dict, compare=False)

    @property
    def reactive(self) -> bool:
        """Whether the run has sensors, actions or assumptions (assume-guarantee verdict)."""
        return bool(self.sensors or self.actions or self.assumptions)

    @property
    def start(self) -> float:
        """The time messages count from: the log's first sample."""
        return float(self.times[0]) if self.origin is None else self.origin


def _fail(
    code: str,
    message: str,
    file: str | None,
    hint: str | None = None,
    line: int | None = None,
    path: str | None = None,
) -> UsageError:
    return UsageError(error(code, message, hint=hint, file=file, line=line, path=path))


#: What a polygon of a trace is: the hint of every V004 about its shape.
_POLYGON_HINT = (
    "a polygon is a list of at least 3 [x, y] points, finite and within 1e12, listed in order "
    "around the shape"
)


def _polygon(value: Any, what: str, file: str | None, path: str) -> FloatArray:
    """``value`` as a polygon's ``[x, y]`` rows (V004 at ``path`` when it is not one)."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except OverflowError:  # an integer too large for a float
        raise _fail(
            "V004", f"{what} has a non-finite coordinate", file, _POLYGON_HINT, path=path
        ) from None
    except (TypeError, ValueError):
        raise _fail(
            "V004", f"{what} is not a list of [x, y] points", file, _POLYGON_HINT, path=path
        ) from None
    if array.ndim != 2 or array.shape[1] != 2 or array.shape[0] < 3:
        raise _fail(
            "V004",
            f"{what} is not a polygon (at least 3 [x, y] points)",
            file,
            _POLYGON_HINT,
            path=path,
        )
    if not np.all(np.isfinite(array)):
        raise _fail("V004", f"{what} has a non-finite coordinate", file, _POLYGON_HINT, path=path)
    if np.any(np.abs(array) > MAX_MAGNITUDE):
        # as a sample's (V024): the shape checks' squared differences would overflow
        raise _fail(
            "V004",
            f"{what} has a coordinate beyond {MAX_MAGNITUDE:g}",
            file,
            _POLYGON_HINT,
            path=path,
        )
    return array


def _polygon_list(value: Any, what: str, file: str | None, path: str) -> list[Any]:
    """``value``, a list of polygons (holes), or empty when left out (V004 when it is not)."""
    if value is None:
        return []
    if not isinstance(value, list):
        raise _fail("V004", f"{what} is not a list of polygons", file, _POLYGON_HINT, path=path)
    return value


def _check_simple(polygon: FloatArray, what: str, file: str | None, path: str) -> None:
    """Refuse (V004) a polygon a mission would refuse: fewer than 3 distinct points, zero
    area, or edges that cross or touch — by the mission loader's own check, so a trace takes
    the shapes a mission takes (shapely's overlays fail on a self-intersecting workspace)."""
    from tlmpc.mission.geometry import check_shape

    _, problems = check_shape(polygon.tolist(), (), what, file or "<input>", lambda _: (0, 0))
    if problems:
        raise _fail("V004", problems[0].message, file, hint=problems[0].hint, path=path)


def _polygons(named: Mapping[str, Any], file: str | None) -> dict[str, FloatArray]:
    """``_polygon`` of every region, converted in one array when all are well formed (a map
    of many regions would spend most of its reading here); any doubt: one by one, for the
    precise error."""
    values = list(named.values())
    try:
        lengths = [len(v) for v in values]
        flat = np.array([p for v in values for p in v], dtype=np.float64)
        fine = (
            all(isinstance(v, list) for v in values)
            and flat.ndim == 2
            and flat.shape[1] == 2
            and min(lengths, default=3) >= 3
            and bool(np.isfinite(flat).all())
        )
    except (TypeError, ValueError, OverflowError):
        fine = False
    if fine:
        fine = bool(np.all(np.abs(flat) <= MAX_MAGNITUDE))
    if not fine:
        return {
            str(k): _polygon(v, f"region {k!r}", file, json_path("regions", str(k)))
            for k, v in named.items()
        }
    # Plain slices (np.split costs microseconds per piece).
    bounds = [0, *itertools.accumulate(lengths)]
    pieces = [flat[a:b] for a, b in itertools.pairwise(bounds)]
    return {str(k): piece for k, piece in zip(named, pieces, strict=True)}


#: The hint of a trace's malformed ``points`` (V002).
_POINTS_HINT = 'write the samples as "points": [[t, x, y], ...], numbers in increasing time'


def _points_row(rows: list[Any]) -> int:
    """The index of the first of ``rows`` that is not three numbers (or one past the last)."""
    for index, row in enumerate(rows):
        try:
            if np.asarray(row, dtype=np.float64).shape != (3,):
                return index
        except (TypeError, ValueError, OverflowError):
            return index
    return len(rows)


def _huge_number(rows: Any) -> tuple[int, int] | None:
    """The row and cell of the first integer of the rows ``rows`` too large for a float
    (None when ``rows`` is not a list of rows)."""
    if not isinstance(rows, list):
        return None
    for index, row in enumerate(rows):
        for cell, value in enumerate(row if isinstance(row, list) else []):
            if isinstance(value, int) and not isinstance(value, bool):
                try:
                    float(value)
                except OverflowError:
                    return index, cell
    return None


def _samples(
    rows: Any,
    file: str | None,
    lines: list[int] | None = None,
    place: CellPlace | None = None,
    origin: SampleOrigin | None = None,
) -> FloatArray:
    """The ``[t, x, y]`` rows (V002, V024 and :func:`check_samples`' codes); ``place``: where
    a sample's cell is written (a CSV's columns), else its JSON path under ``points``;
    ``origin``: where a sample came from, for a log without lines (a bag's messages)."""
    # rows of a trace.json's `points` when no reader says where they came from
    where = json_path("points") if place is None and lines is None and origin is None else None
    if where is not None:

        def place(index: int, cell: int) -> dict[str, Any]:
            return {"path": json_path("points", index, cell)}

    try:
        array = np.asarray(rows, dtype=np.float64)
    except OverflowError:  # an integer too large for a float: beyond any time or place
        huge = _huge_number(rows)
        raise _fail(
            "V024" if huge is not None else "V002",
            (f"sample {huge[0]} has" if huge is not None else "`points` is")
            + f" a number beyond {MAX_MAGNITUDE:g} (an integer too large for a float)",
            file,
            hint="a corrupt sample, or times in nanoseconds: times are seconds and positions "
            "the mission's units"
            if huge is not None
            else _POINTS_HINT,
            path=(json_path("points", *huge) if huge is not None else where) if where else None,
        ) from None
    except (TypeError, ValueError):
        array = None
    if array is None or array.ndim != 2 or array.shape[1] != 3:
        if isinstance(rows, list) and not rows:
            array = np.zeros((0, 3))
        else:
            row = _points_row(rows) if isinstance(rows, list) else None
            raise _fail(
                "V002",
                "points must be rows of three numbers [t, x, y]"
                + (f" (sample {row} is not)" if row is not None else ""),
                file,
                _POINTS_HINT,
                path=json_path("points", row) if where and row is not None else where,
            )
    try:
        check_samples(
            array[:, 0],
            array[:, 1],
            array[:, 2],
            file=file,
            lines=lines,
            place=place,
            origin=origin,
        )
    except UsageError as exc:
        raise UsageError([_with_path(d, where) for d in exc.diagnostics]) from None
    return array


def _with_path(diagnostic: Diagnostic, path: str | None) -> Diagnostic:
    """``diagnostic``, at ``path`` when it has no place of its own."""
    if path is None or diagnostic.line is not None or diagnostic.path is not None:
        return diagnostic
    return dataclasses.replace(diagnostic, path=path)


def certifying_speed(speed: Any) -> float | None:
    """``max_speed`` when it can back the robustness certificate, else None.

    The certificate assumes the robot moves at most ``max_speed`` between samples: a speed
    that is not a positive finite number vouches for nothing.  (Whether the samples themselves
    move faster is checked by the certificate, which then says where.)
    """
    if isinstance(speed, bool) or not isinstance(speed, int | float):
        return None
    try:
        value = float(speed)
    except OverflowError:  # an integer too large for a float
        return None
    return value if math.isfinite(value) and value > 0 else None


def _formula(
    text: Any,
    names: set[str],
    file: str | None,
    *,
    assumption: int | None = None,
    source: str | None = None,
) -> Formula:
    """The formula ``text`` (the task, or assumption number ``assumption``), its diagnostics
    placed in the string that holds it in ``source``, the document's JSON text, when given."""
    path = json_path("ltl") if assumption is None else json_path("assumptions", assumption)
    if not isinstance(text, str):
        if assumption is not None:
            raise _fail(
                "V034",
                f"assumption {assumption} is not an LTL string",
                file,
                hint='write each assumption as an LTL formula in a string, e.g. "G F !alarm"',
                path=path,
            )
        raise _fail(
            "V006",
            "the trace has no `ltl` task"
            + ("" if text is None else f" (`ltl` is {type(text).__name__}, not a string)"),
            file,
            hint='give the task as an LTL formula in a string, e.g. "ltl": "F a & G !b"',
            path=path,
        )
    from tlmpc.base.errors import InvalidInputError
    from tlmpc.ltl.parser import parse_ltl  # lark: only when a formula is read as text

    try:
        formula = parse_ltl(text, file=file)
    except InvalidInputError as exc:
        raise UsageError([_in_string(d, text, path, source) for d in exc.diagnostics]) from None
    unknown = sorted(formula.props() - names)
    if not unknown:
        return formula
    first = _name_position(text, unknown[0])
    if assumption is not None:
        problem = error(
            "V034",
            f"assumption {assumption} names unknown propositions: {', '.join(unknown)}",
            hint="an assumption speaks of the trace's regions, sensors and actions",
            file=file,
            line=first[0],
            col=first[1],
        )
    else:
        problem = error(
            "V007",
            f"the task names unknown regions: {', '.join(unknown)}",
            hint="every region in `ltl` must be defined under `regions` (a reactive trace's "
            "sensors and actions under `sensors` and `actions`)",
            file=file,
            line=first[0],
            col=first[1],
        )
    raise UsageError(_in_string(problem, text, path, source))


def _name_position(text: str, name: str) -> tuple[int | None, int | None]:
    """The line and column (in ``text``, lines ending at ``\\n``) of the first whole-word
    occurrence of the proposition ``name``."""
    import re

    found = re.search(rf"(?<![\w.]){re.escape(name)}(?![\w.])", text)
    if found is None:
        return None, None
    before = text[: found.start()]
    return before.count("\n") + 1, found.start() - before.rfind("\n")


def _in_string(diagnostic: Diagnostic, value: str, path: str, source: str | None) -> Diagnostic:
    """A diagnostic about the formula string ``value`` (its line and column counted in the
    string), placed at ``path`` and, with the document's JSON text ``source``, at the line
    and column of that character in the file; without it, at the path alone."""
    from tlmpc.io.json_places import parse_json_path, string_char_places, text_place, value_offset

    within = diagnostic.line, diagnostic.col
    placed = dataclasses.replace(diagnostic, path=path, line=None, col=None)
    if source is None:
        return placed
    start = value_offset(source, parse_json_path(path) or [])
    places = string_char_places(source, start) if start is not None else None
    if places is None:
        return placed
    offset = 0
    if within[0] is not None:
        lines = value.split("\n")
        line = min(max(within[0], 1), len(lines))
        offset = sum(len(part) + 1 for part in lines[: line - 1]) + (within[1] or 1) - 1
    line, col = text_place(source, places[min(max(offset, 0), len(places) - 1)])
    return dataclasses.replace(placed, line=line, col=col)


def _names(
    document: Mapping[str, Any], key: str, regions: set[str], file: str | None
) -> tuple[str, ...]:
    value = document.get(key)
    if value is None:
        return ()
    path = json_path(key)
    if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
        raise _fail(
            "V033",
            f"`{key}` is not a list of names",
            file,
            hint=f'write `{key}` as a list of names, e.g. "{key}": ["alarm"]',
            path=path,
        )
    clash = sorted(set(value) & regions)
    if clash or len(set(value)) != len(value):
        twice = clash or sorted(v for v in set(value) if value.count(v) > 1)
        raise _fail(
            "V033",
            f"`{key}` names {', '.join(map(repr, twice))} twice (or also as a region)",
            file,
            hint="a name is a region, a sensor or an action, once",
            path=json_path(key, value.index(twice[0])),
        )
    return tuple(value)


def _reactive_fields(
    document: Mapping[str, Any],
    regions: set[str],
    file: str | None,
    signals: Mapping[str, Signal] | None,
    source: str | None,
) -> dict[str, Any]:
    """The sensors, actions, assumptions and signals of a reactive trace (all empty else)."""
    sensors = _names(document, "sensors", regions, file)
    actions = _names(document, "actions", regions | set(sensors), file)
    texts = document.get("assumptions") or []
    if not isinstance(texts, list):
        raise _fail(
            "V034",
            "`assumptions` is not a list of LTL strings",
            file,
            hint='write the assumptions as a list of LTL strings, e.g. ["G F !alarm"]',
            path=json_path("assumptions"),
        )
    known = regions | set(sensors) | set(actions)
    assumptions = tuple(
        _formula(text, known, file, assumption=index, source=source)
        for index, text in enumerate(texts)
    )
    if signals is None:
        signals = signals_of_document(document, [*sensors, *actions], file)
    return {
        "sensors": sensors,
        "actions": actions,
        "assumptions": assumptions,
        "signals": dict(signals),
    }


def from_document(
    document: Mapping[str, Any],
    *,
    file: str | None = None,
    convention: str | None = None,
    signals: Mapping[str, Signal] | None = None,
    source: str | None = None,
) -> TraceInput:
    """Validate a ``tlmpc.trace/1`` document (``signals``, read from a log, replace the
    document's own).

    Each diagnostic names the value it is about by its JSON path; with ``source``, the
    document's JSON text, it is placed at that value's line and column too."""
    try:
        return _validated(document, file, convention, signals, source)
    except UsageError as exc:
        if source is None:
            raise
        raise UsageError([_placed(d, source) for d in exc.diagnostics]) from None


def _placed(diagnostic: Diagnostic, source: str) -> Diagnostic:
    """``diagnostic`` at the line and column of the value its JSON path names in ``source``
    (unless it has a line already)."""
    from tlmpc.io.json_places import json_place

    if diagnostic.path is None or diagnostic.line is not None:
        return diagnostic
    found = json_place(source, diagnostic.path)
    if found is None:
        return diagnostic
    return dataclasses.replace(diagnostic, line=found[0], col=found[1])


def _validated(
    document: Mapping[str, Any],
    file: str | None,
    convention: str | None,
    signals: Mapping[str, Signal] | None,
    source: str | None,
) -> TraceInput:
    fmt = document.get("format")
    if not isinstance(fmt, str) or not fmt.startswith("tlmpc.trace/"):
        raise _fail(
            "V001",
            f"not a tlmpc trace (format {fmt!r})",
            file,
            hint="pass a trace.json written by `tlmpc compile`, or a CSV with --mission",
            path=json_path("format"),
        )
    regions_doc = document.get("regions")
    if not isinstance(regions_doc, dict):
        raise _fail(
            "V004",
            "the trace has no `regions`",
            file,
            hint='give the regions as an object of name -> polygon, e.g. "regions": '
            '{"a": [[0, 0], [1, 0], [1, 1]]}',
            path=json_path("regions"),
        )
    regions = _polygons(regions_doc, file)
    for name, polygon in regions.items():
        _check_simple(polygon, f"region {name!r}", file, json_path("regions", name))
    samples = _samples(document.get("points"), file)
    loop = document.get("loop_start")
    if loop is not None and (
        not isinstance(loop, int) or isinstance(loop, bool) or not 0 <= loop < len(samples)
    ):
        raise _fail(
            "V008",
            f"loop_start {loop!r} is not a sample index",
            file,
            hint=f"loop_start is null, or the index (0 to {len(samples) - 1}) of the sample "
            "from which the run repeats",
            path=json_path("loop_start"),
        )
    workspace = document.get("workspace") or {}
    if not isinstance(workspace, dict):
        raise _fail(
            "V004",
            "the trace's `workspace` is not a mapping {boundary, holes}",
            file,
            hint='write it as "workspace": {"boundary": [[x, y], ...], "holes": [...]}',
            path=json_path("workspace"),
        )
    boundary = workspace.get("boundary")
    boundary_path = json_path("workspace", "boundary")
    boundary_polygon = (
        _polygon(boundary, "workspace boundary", file, boundary_path) if boundary else None
    )
    holes_path = ("workspace", "holes")
    holes = tuple(
        _polygon(h, f"hole {i}", file, json_path(*holes_path, i))
        for i, h in enumerate(
            _polygon_list(workspace.get("holes"), "`workspace.holes`", file, json_path(*holes_path))
        )
    )
    components_doc = workspace.get("components") or []
    if not isinstance(components_doc, list) or not all(
        isinstance(c, dict) and "boundary" in c for c in components_doc
    ):
        raise _fail(
            "V004",
            "workspace.components is not a list of {boundary, holes}",
            file,
            hint='write it as "components": [{"boundary": [[x, y], ...], "holes": [...]}]',
            path=json_path("workspace", "components"),
        )
    components = tuple(
        (
            _polygon(
                c["boundary"],
                f"boundary of component {k}",
                file,
                json_path("workspace", "components", k, "boundary"),
            ),
            tuple(
                _polygon(
                    h,
                    f"hole {i} of component {k}",
                    file,
                    json_path("workspace", "components", k, "holes", i),
                )
                for i, h in enumerate(
                    _polygon_list(
                        c.get("holes"),
                        f"`holes` of component {k}",
                        file,
                        json_path("workspace", "components", k, "holes"),
                    )
                )
            ),
        )
        for k, c in enumerate(components_doc)
    )
    if boundary_polygon is not None:
        _check_simple(boundary_polygon, "workspace boundary", file, boundary_path)
    for i, hole in enumerate(holes):
        _check_simple(hole, f"hole {i}", file, json_path(*holes_path, i))
    for k, (outer, inner) in enumerate(components):
        component_path = ("workspace", "components", k)
        _check_simple(
            outer, f"boundary of component {k}", file, json_path(*component_path, "boundary")
        )
        for i, hole in enumerate(inner):
            _check_simple(
                hole, f"hole {i} of component {k}", file, json_path(*component_path, "holes", i)
            )
    chosen = convention or document.get("boundary") or "right"
    if chosen not in ("right", "closed"):
        raise _fail(
            "V009",
            f"unknown boundary convention {chosen!r}",
            file,
            hint="use right or closed",
            path=json_path("boundary"),
        )
    speed = document.get("max_speed")
    end = document.get("end")
    if loop is not None and loop == len(samples) - 1:
        # A loop of the last sample alone: the robot stays there forever.
        loop, end = None, ("stay" if end in (None, "loop") else end)
    if (
        end not in (None, "stay", "open", "loop")
        or (end == "loop" and loop is None)
        or (end in ("stay", "open") and loop is not None)
    ):
        raise _fail(
            "V021",
            f"`end` is {end!r} with loop_start {loop!r}",
            file,
            hint="`end` is stay or open without a loop_start, loop with one (or leave it out)",
            path=json_path("end"),
        )
    ending: Ending = "loop" if loop is not None else ("stay" if end == "stay" else "open")
    reactive = _reactive_fields(document, set(regions), file, signals, source)
    propositions = set(regions) | set(reactive["sensors"]) | set(reactive["actions"])
    return TraceInput(
        times=samples[:, 0].copy(),
        points=samples[:, 1:].copy(),
        loop_start=loop,
        formula=_formula(document.get("ltl"), propositions, file, source=source),
        regions=regions,
        boundary_polygon=boundary_polygon,
        holes=holes,
        components=components if boundary else (),
        convention=chosen,
        ending=ending,
        max_speed=certifying_speed(speed),
        source=file,
        radius=_radius(document.get("radius"), file),
        **reactive,
    )


def _radius(value: Any, file: str | None) -> float:
    if value is None:
        return 0.0
    try:
        radius = float(value) if isinstance(value, int | float) else math.nan
    except OverflowError:  # an integer too large for a float
        radius = math.inf
    if isinstance(value, bool) or not math.isfinite(radius) or radius < 0:
        raise _fail(
            "V004",
            f"radius {value!r} is not a number >= 0",
            file,
            hint="radius is the robot body's radius, a finite number >= 0 (0: a point robot)",
            path=json_path("radius"),
        )
    return radius


def read_csv(path: Path, columns: Sequence[str] | None = None) -> tuple[FloatArray, list[int]]:
    """A CSV log's ``[t, x, y]`` rows (see :mod:`tlmpc.importers.logs`), with line numbers."""
    from tlmpc.importers.logs import read_csv_log

    log = read_csv_log(path, columns)
    lines = list(log.lines)
    return _samples(log.samples, str(path), lines), lines


#: Bounds checked on the file before a CSV trace is parsed, so memory stays bounded: a
#: sample costs a few hundred bytes once parsed.
MAX_CSV_BYTES = 256 * 1024 * 1024
MAX_CSV_ROWS = 2_000_000
MAX_CSV_LINE = 4096


class _CsvExtent(NamedTuple):
    """What the size checks see of a CSV file (read until a limit is passed)."""

    size: int
    rows: int
    longest: int
    #: the number of the first line longer than :data:`MAX_CSV_LINE`, if one was met
    long_line: int | None


def _csv_extent(path: Path) -> _CsvExtent:
    """Bytes, rows and longest line of a CSV file, read in chunks until a limit is passed;
    lines end where the log readers end them (see :func:`tlmpc.importers.logs.split_lines`)."""
    rows = 0
    longest = 0
    current = 0
    size = 0
    long_line = None
    after_cr = False  # the chunk before ended with a CR: a LF now is the rest of its CR LF
    try:
        with open(path, "rb") as stream:  # chunks: /dev/zero or a huge log stop early
            while chunk := stream.read(1 << 20):
                size += len(chunk)
                text = chunk[1:] if after_cr and chunk.startswith(b"\n") else chunk
                after_cr = chunk.endswith(b"\r")
                # a line ends at LF, CR LF or a lone CR (as the log readers end it); two
                # replaces and a split are three times as fast as a regular expression's split
                lines = text.replace(b"\r\n", b"\n").replace(b"\r", b"\n").split(b"\n")
                ended = [current + len(lines[0]), *map(len, lines[1:-1])][: len(lines) - 1]
                for offset, length in enumerate(ended):
                    if length > MAX_CSV_LINE and long_line is None:
                        long_line = rows + 1 + offset
                longest = max(longest, *ended) if ended else longest
                rows += len(lines) - 1
                current = len(lines[-1]) if len(lines) > 1 else current + len(lines[0])
                if current > MAX_CSV_LINE and long_line is None:
                    long_line = rows + 1
                longest = max(longest, current)
                if size > MAX_CSV_BYTES or rows > MAX_CSV_ROWS or longest > MAX_CSV_LINE:
                    break
    except OSError as exc:
        raise _fail("U001", f"cannot read {path}: {exc.strerror or exc}", str(path)) from None
    return _CsvExtent(size, rows, longest, long_line)


def is_large_csv(path: Path) -> bool:
    """Whether the whole-log reader refuses the CSV for its size alone (U038): a log to
    stream instead."""
    size, rows, longest, _ = _csv_extent(path)
    return (size > MAX_CSV_BYTES or rows > MAX_CSV_ROWS) and longest <= MAX_CSV_LINE


def check_csv_file(path: Path) -> None:
    """Refuse (U038) a CSV trace too large to verify, reading it in chunks (never whole)."""
    size, rows, longest, long_line = _csv_extent(path)
    if size > MAX_CSV_BYTES or rows > MAX_CSV_ROWS:
        raise _fail(
            "U038",
            f"the CSV trace is too large (more than {MAX_CSV_ROWS:,} rows or "
            f"{MAX_CSV_BYTES // 2**20} MiB)",
            str(path),
            hint="thin the log out (keep every k-th row) to view, plot or read it whole; "
            "`tlmpc verify` streams a log of any length",
        )
    if longest > MAX_CSV_LINE:
        raise _fail(
            "U038",
            f"the CSV trace has a line longer than {MAX_CSV_LINE} bytes"
            + (f" (line {long_line})" if long_line is not None else ""),
            str(path),
            hint="a CSV trace has short t,x,y rows; is this the right file?",
            line=long_line,
        )


@dataclass(frozen=True, slots=True)
class LogOptions:
    """How to read a robot log (the flags every command that takes a log shares)."""

    topic: str | None = None  # bags: the pose topic
    columns: Sequence[str] | None = None  # CSV: the time and position columns
    transform: tuple[float, float, float] | None = None  # x, y, yaw into the mission's frame
    frame: str | None = None  # bags: express the poses in this frame through the bag's tf


def read_trace(
    path: Path,
    mission: Path | Mission | None,
    convention: str | None = None,
    options: LogOptions = LogOptions(),
) -> TraceInput:
    """The one way a command reads a trajectory: a ``trace.json`` (self-contained), or a robot
    log — CSV, ROS 1 ``.bag``, ROS 2 bag directory (sqlite3 or MCAP), ``.mcap`` — checked
    against ``mission`` (a mission file, or a mission already loaded) for its regions and task.
    ``tlmpc verify``, ``tlmpc plot --log`` and ``tlmpc view --log`` all read through here, so
    they take the same formats."""
    from tlmpc.importers.logs import is_log, path_problem

    if is_log(path):
        if mission is None:
            raise _fail(
                "V010",
                "a robot log needs --mission MISSION.yaml for its regions and task",
                str(path),
            )
        if isinstance(mission, Path):
            mission = load_log_mission(mission)
        return _log_trace(path, mission, convention, options)
    if path.is_symlink() and not path.exists():  # a link loop (meant as a folder?) or to nothing
        raise _fail(
            "U001",
            f"cannot read {path}: {path_problem(path)}",
            str(path),
            hint="point the link at a trace.json, a log or a folder of logs",
        )
    from tlmpc.io.artifacts import MAX_ARTIFACT_BYTES, parse_json
    from tlmpc.io.inputs import read_text

    text = read_text(
        path, limit=MAX_ARTIFACT_BYTES, code="U001", too_large_code="U040", what="artifact"
    )
    # non-finite numbers are read, so that the verifier reports the sample where it is
    document = parse_json(text, path, finite=False)
    return from_document(document, file=str(path), convention=convention, source=text)


def load_log_mission(mission_path: Path) -> Mission:
    """The mission a log is checked against (its loader's diagnostics, exit 2)."""
    from tlmpc.base.errors import InvalidInputError
    from tlmpc.mission.load import load_mission

    try:
        return load_mission(mission_path)
    except InvalidInputError as exc:
        raise UsageError(exc.diagnostics) from None


def mission_document(path: Path, mission_path: Path | None) -> dict[str, Any]:
    """A ``tlmpc.trace/1`` document without samples: the task, regions, workspace, convention,
    ``max_speed`` and body radius that ``mission_path`` gives the log at ``path`` (see
    :func:`positions_document`)."""
    if mission_path is None:
        raise _fail(
            "V010", "a CSV trace needs --mission MISSION.yaml for its regions and task", str(path)
        )
    return positions_document(load_log_mission(mission_path))


def positions_document(mission: Mission) -> dict[str, Any]:
    """``mission`` as a sample-less ``tlmpc.trace/1`` document for the readers that take
    positions only (many logs at once, a streamed log, the live monitor): refused (U110, at
    the mission file, whatever log it was meant for) when the mission is reactive."""
    if mission.reactive is not None:
        name = mission.source or "the mission"
        raise _fail(
            "U110",
            f"{name} is a reactive mission: verifying many logs at once, streaming a "
            "long log and live monitoring read positions only, not sensor values",
            mission.source,
            hint=f"verify each log on its own: tlmpc verify --mission {name} LOG "
            "(a log over the size limit: thin it out first)",
        )
    return _mission_fields(mission)


def _mission_fields(mission: Mission) -> dict[str, Any]:
    from tlmpc.ltl.printer import to_text
    from tlmpc.mission.body import body_radius

    return {
        "format": "tlmpc.trace/1",
        "ltl": to_text(mission.formula),
        "regions": {r.name: [list(p) for p in r.polygon] for r in mission.regions},
        "workspace": mission.workspace.to_json(),
        "boundary": mission.options.boundary,
        "max_speed": mission.robot.max_speed,
        "radius": body_radius(mission.robot),
        "points": [],
        "loop_start": None,
        **_reactive_document(mission),
    }


def _reactive_document(mission: Mission) -> dict[str, Any]:
    """A reactive mission's sensors, actions and assumptions as trace fields (none else)."""
    from tlmpc.ltl.printer import to_text

    if mission.reactive is None:
        return {}
    return {
        "sensors": list(mission.reactive.sensor_names),
        "actions": list(mission.reactive.actions),
        "assumptions": [to_text(part.formula) for part in mission.reactive.assumptions],
    }


def _log_trace(
    path: Path, mission: Mission, convention: str | None, options: LogOptions
) -> TraceInput:
    """A log's samples with the mission's regions, task, workspace, speed and body."""
    from tlmpc.importers.logs import CSV_SUFFIXES, read_log

    if path.suffix.lower() in CSV_SUFFIXES and path.is_file():
        check_csv_file(path)  # bounded before parsing
    log = read_log(
        path,
        topic=options.topic,
        columns=options.columns,
        transform=options.transform,
        frame=options.frame,
    )
    from tlmpc.importers.logs import SampleColumns, SampleMessages

    origin = SampleMessages(path, options.topic, log.messages) if log.messages is not None else None
    samples = _samples(
        log.samples, str(path), list(log.lines) or None, SampleColumns(path, log), origin
    )
    document = _mission_fields(mission)
    document["points"] = samples.tolist()
    signals = None
    if mission.reactive is not None:
        from tlmpc.verify.log_signals import read_signals

        signals = read_signals(path, mission.reactive, options.columns)
    return from_document(document, file=str(path), convention=convention, signals=signals)


def from_csv(
    path: Path,
    mission_path: Path | None,
    convention: str | None,
    *,
    topic: str | None = None,
    columns: Sequence[str] | None = None,
    transform: tuple[float, float, float] | None = None,
    frame: str | None = None,
) -> TraceInput:
    """A logged trajectory (CSV or ROS bag) checked against a mission file's regions and task.

    ``frame`` (bags): the poses are expressed in that frame through the bag's tf."""
    if mission_path is None:
        raise _fail(
            "V010", "a CSV trace needs --mission MISSION.yaml for its regions and task", str(path)
        )
    options = LogOptions(topic=topic, columns=columns, transform=transform, frame=frame)
    return _log_trace(path, load_log_mission(mission_path), convention, options)
