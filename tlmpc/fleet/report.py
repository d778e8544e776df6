"""The fleet report: one self-contained HTML page about a batch of verified logs.

* verdicts per robot and day (a table of counts);
* violations per conjunct (how many logs, how many violations);
* a heat map per mission: where on the map violations happen (a grid of cells shaded by how
  many violations fall in each, over the workspace, its holes and the regions);
* every log with its verdict and first violation, linked to its own view (``tlmpc view``'s
  page, written beside the report).

Robot and day come from each log's path (:func:`robot_and_day`).  Every piece of text from a
log, a path or a mission is escaped (HTML, and control and direction characters as
visible escapes); the page loads nothing (no script, no network).
"""

from __future__ import annotations

import contextlib
import hashlib
import html
import math
import re
import shlex
from collections import Counter, defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any
from urllib.parse import quote

from tlmpc.base.errors import Diagnostic, UsageError, error, printable
from tlmpc.fleet.job import Job, Options
from tlmpc.fleet.output import check_output, visible, write_atomically
from tlmpc.verify.trace_input import LogOptions

DATE = re.compile(r"\d{4}-\d{2}-\d{2}")

#: Views written beside the report at most (violated logs first); the others get the command.
VIEW_LIMIT = 1000

#: Columns of a heat map's grid.
HEAT_COLUMNS = 48

#: Hexadecimal digits of a page's SHA-256 in its view's name.
VIEW_DIGITS = 16

#: The names of views this report writes (``STEM-DIGEST.html``), and those earlier versions
#: wrote (``NNNNN-STEM.html``): what :func:`_remove_unlinked` may remove.
VIEW_NAME = re.compile(
    rf"[A-Za-z0-9._-]{{0,60}}-[0-9a-f]{{{VIEW_DIGITS}}}\.html|[0-9]{{5}}-[A-Za-z0-9._-]{{0,60}}\.html"
)

STYLE = """
body { font: 14px system-ui, sans-serif; color: #222; margin: 16px 24px; }
h1 { font-size: 20px; } h2 { font-size: 16px; margin-top: 28px; }
table { border-collapse: collapse; margin: 8px 0; }
th, td { border: 1px solid #ddd; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #f3f3f3; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
.satisfied { color: #17692c; font-weight: bold; }
.violated { color: #b00020; font-weight: bold; }
.inconclusive { color: #8a5a00; font-weight: bold; }
.error { color: #555; font-weight: bold; }
.formula { font-family: ui-monospace, monospace; font-size: 12px; }
svg { background: #fafafa; border: 1px solid #ddd; }
.workspace { fill: #fff; stroke: #333; }
.hole { fill: #9a9a9a; stroke: #333; }
.region { fill: none; stroke: #3b6fb6; stroke-dasharray: 4 2; }
.label { font: 11px system-ui, sans-serif; fill: #3b6fb6; }
.heat { fill: #b00020; }
"""


def robot_and_day(
    log: str, root: PurePosixPath, pattern: re.Pattern[str] | None
) -> tuple[str, str]:
    """The robot and the day of a log.

    With ``pattern``: its named groups ``robot`` and ``day`` searched in the log's path (a group
    that is missing or does not match falls back to the rule below).  Without: the day is the
    first ``YYYY-MM-DD`` in the path (else ``undated``); the robot is the first folder below the
    batch's common folder whose name is not that date, else the file's name without the date.
    """
    path = PurePosixPath(log)
    found: dict[str, str] = {}
    if pattern is not None:
        match = pattern.search(path.as_posix())
        if match is not None:
            found = {k: v for k, v in match.groupdict().items() if v}
    date = DATE.search(path.as_posix())
    day = found.get("day") or (date.group(0) if date else "undated")
    robot = found.get("robot")
    if robot is None:
        try:
            parts = path.relative_to(root).parts
        except ValueError:
            parts = path.parts
        folders = [p for p in parts[:-1] if not DATE.fullmatch(p)]
        if folders:
            robot = folders[0]
        else:
            stem = DATE.sub("", PurePosixPath(parts[-1] if parts else log).stem)
            robot = stem.strip("_-. ") or "unnamed"
    return robot, day


def group_pattern(group: str | None) -> re.Pattern[str] | None:
    """``--group REGEX`` compiled (F009 when it is not a regular expression)."""
    if group is None:
        return None
    try:
        return re.compile(group)
    except re.error as exc:
        raise UsageError(
            error(
                "F009",
                f"--group {group!r} is not a regular expression: {exc}",
                hint="for example --group '(?P<robot>[^/]+)/(?P<day>[0-9-]{10})'",
                file="<command line>",
            )
        ) from None


def _common_root(logs: Sequence[str]) -> PurePosixPath:
    parents = [PurePosixPath(log).parent.parts for log in logs]
    if not parents:
        return PurePosixPath(".")
    common: list[str] = []
    for column in zip(*parents, strict=False):
        if len(set(column)) != 1:
            break
        common.append(column[0])
    return PurePosixPath(*common) if common else PurePosixPath(".")


def _e(value: Any) -> str:
    """Text for the page: a file name's bytes that are not UTF-8 as ``\\xNN``, control and
    direction characters escaped as everywhere else (:func:`printable`), then HTML-escaped."""
    return html.escape(printable(visible(str(value)), keep=""), quote=True)


def _href(link: str) -> str:
    """A link to a file written beside the report, its name's bytes percent-encoded."""
    return html.escape(quote(link, errors="surrogateescape"), quote=True)


def _verdict(verdict: str) -> str:
    return f'<span class="{_e(verdict)}">{_e(verdict)}</span>'


def _number(value: float | None, digits: int = 4) -> str:
    if value is None:
        return ""
    return f"{value:.{digits}g}"


def _robots_by_day(rows: Sequence[Mapping[str, Any]], places: Mapping[str, tuple[str, str]]) -> str:
    days = sorted({places[r["log"]][1] for r in rows})
    robots = sorted({places[r["log"]][0] for r in rows})
    cells: dict[tuple[str, str], Counter[str]] = defaultdict(Counter)
    for row in rows:
        cells[places[row["log"]]][row["verdict"]] += 1
    head = "".join(f"<th>{_e(d)}</th>" for d in days)
    body = []
    for robot in robots:
        line = [f"<th>{_e(robot)}</th>"]
        for day in days:
            counts = cells.get((robot, day))
            if not counts:
                line.append("<td></td>")
                continue
            parts = [
                f'<span class="{v}">{counts[v]} {v}</span>'
                for v in ("violated", "inconclusive", "satisfied", "error")
                if counts[v]
            ]
            line.append(f"<td>{'<br>'.join(parts)}</td>")
        body.append(f"<tr>{''.join(line)}</tr>")
    return f"<table><tr><th>robot \\ day</th>{head}</tr>{''.join(body)}</table>"


def _conjuncts(rows: Sequence[Mapping[str, Any]]) -> str:
    logs: Counter[str] = Counter()
    violations: Counter[str] = Counter()
    for row in rows:
        for conjunct in row["conjuncts"]:
            if conjunct["verdict"] == "violated":
                logs[conjunct["conjunct"]] += 1
        seen = set()
        for violation in row.get("violations") or []:
            violations[violation["conjunct"]] += 1
            seen.add(violation["conjunct"])
        if "workspace" in seen:
            logs["workspace"] += 1
    if not logs:
        return "<p>No violations.</p>"
    lines = [
        f'<tr><td class="formula">{_e(name)}</td><td class="n">{logs[name]}</td>'
        f'<td class="n">{violations[name]}</td></tr>'
        for name in sorted(logs, key=lambda n: (-logs[n], n))
    ]
    return (
        "<table><tr><th>conjunct</th><th>logs violating it</th><th>violations</th></tr>"
        + "".join(lines)
        + "</table>"
    )


def _ring(points: Sequence[Sequence[float]], transform: Any) -> str:
    return " ".join(f"{x:.2f},{y:.2f}" for x, y in (transform(p) for p in points))


def _heat_map(mission: str, document: Mapping[str, Any], rows: Sequence[Mapping[str, Any]]) -> str:
    workspace = document.get("workspace") or {}
    outlines: list[Sequence[Sequence[float]]] = list(document["regions"].values())
    if workspace.get("boundary"):
        outlines.append(workspace["boundary"])
    points = [(float(x), float(y)) for ring in outlines for x, y in ring]
    hits = [
        (float(v["x"]), float(v["y"]))
        for row in rows
        for v in row.get("violations") or []
        if v.get("x") is not None and v.get("y") is not None
    ]
    xs = [p[0] for p in points + hits] or [0.0, 1.0]
    ys = [p[1] for p in points + hits] or [0.0, 1.0]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    span = max(x1 - x0, y1 - y0, 1e-9)
    x1, y1 = max(x1, x0 + 1e-9 * span), max(y1, y0 + 1e-9 * span)
    width = 640.0
    scale = width / (x1 - x0)
    height = max(120.0, min(900.0, (y1 - y0) * scale))
    scale = min(scale, height / (y1 - y0))

    def at(p: Sequence[float]) -> tuple[float, float]:
        return (float(p[0]) - x0) * scale, height - (float(p[1]) - y0) * scale

    size = (x1 - x0) / HEAT_COLUMNS
    rows_count = max(1, math.ceil((y1 - y0) / size))
    counts: Counter[tuple[int, int]] = Counter(
        (min(int((x - x0) / size), HEAT_COLUMNS - 1), min(int((y - y0) / size), rows_count - 1))
        for x, y in hits
    )
    most = max(counts.values(), default=1)
    shapes = []
    if workspace.get("boundary"):
        shapes.append(f'<polygon class="workspace" points="{_ring(workspace["boundary"], at)}"/>')
        for hole in workspace.get("holes") or []:
            shapes.append(f'<polygon class="hole" points="{_ring(hole, at)}"/>')
    for (i, j), count in sorted(counts.items()):
        left, top = at((x0 + i * size, y0 + (j + 1) * size))
        opacity = 0.15 + 0.85 * count / most
        shapes.append(
            f'<rect class="heat" x="{left:.2f}" y="{top:.2f}" width="{size * scale:.2f}" '
            f'height="{size * scale:.2f}" fill-opacity="{opacity:.3f}">'
            f"<title>{count} violation{'s' if count != 1 else ''}</title></rect>"
        )
    for name, ring in document["regions"].items():
        shapes.append(f'<polygon class="region" points="{_ring(ring, at)}"/>')
        cx = sum(p[0] for p in ring) / len(ring)
        cy = sum(p[1] for p in ring) / len(ring)
        lx, ly = at((cx, cy))
        shapes.append(f'<text class="label" x="{lx:.2f}" y="{ly:.2f}">{_e(name)}</text>')
    return (
        f"<h3>{_e(mission)}: {len(hits)} violation{'s' if len(hits) != 1 else ''} located</h3>"
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
        f'viewBox="0 0 {width:.2f} {height:.2f}">{"".join(shapes)}</svg>'
    )


@dataclass(frozen=True, slots=True)
class Views:
    """The views written beside the report (their links, by log) and the logs that have
    none because ``tlmpc view`` refuses them (its diagnostic, by log)."""

    links: Mapping[str, str] = field(default_factory=dict)
    refused: Mapping[str, Diagnostic] = field(default_factory=dict)


def views_folder(report: Path) -> Path:
    """The folder of the logs' views beside the report (``fleet.views/`` for ``fleet.html``)."""
    return report.with_name(report.stem + ".views")


def _check_views_folder(folder: Path) -> None:
    """Refuse (F007) a views folder that is a link (never written through) or not a folder."""
    if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
        what = (
            "is a symbolic link (the report's views are never written through one)"
            if folder.is_symlink()
            else "exists and is not a folder (the report's views are written there)"
        )
        raise UsageError(
            error(
                "F007",
                f"{folder} {what}",
                hint="move it away, or choose another --report name (the views of NAME.html "
                "go in NAME.views)",
                file=str(folder),
            )
        )


def check_report(path: Path) -> None:
    """Refuse (F007), before any log is verified, a report or a views folder the batch
    could not write at its end."""
    check_output(path)
    _check_views_folder(views_folder(path))


def _views(
    rows: Sequence[Mapping[str, Any]],
    folder: Path,
    link_base: str,
    reading: Mapping[str, Options],
) -> Views:
    """Write each log's own view (violated first, at most :data:`VIEW_LIMIT`), read as the
    batch read it (``reading``: each log's options).

    A page is named after its log and its own bytes, so it never replaces a page an earlier
    report links to: a run cut short leaves that report and its pages as they were."""
    from tlmpc.base.errors import TlmpcError
    from tlmpc.view import render_html, scene_from_log

    order = sorted(
        (r for r in rows if r["verdict"] != "error" and r.get("mission")),
        key=lambda r: (r["verdict"] != "violated", r["verdict"] != "inconclusive"),
    )
    links: dict[str, str] = {}
    refused: dict[str, Diagnostic] = {}
    for row in order[:VIEW_LIMIT]:
        options = reading.get(row["log"], Options())
        try:
            scene = scene_from_log(
                Path(row["log"]),
                Path(row["mission"]),
                LogOptions(
                    topic=options.topic,
                    columns=options.columns,
                    transform=options.transform,
                    frame=options.frame,
                ),
                convention=options.boundary,
                assume_stay=options.assume_stay,
                loop_from=options.loop_from,
            )
        except TlmpcError as exc:  # too large for a view (a streamed log): the report says so
            if exc.diagnostics:
                refused[row["log"]] = exc.diagnostics[0]
            continue
        page = render_html(scene).encode("utf-8")
        stem = re.sub(r"[^A-Za-z0-9._-]+", "_", Path(row["log"]).stem)[:60]
        name = f"{stem}-{hashlib.sha256(page).hexdigest()[:VIEW_DIGITS]}.html"
        _check_views_folder(folder)
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise UsageError(
                error("F007", f"cannot write {folder}: {exc.strerror or exc}", file=str(folder))
            ) from None
        write_atomically(folder / name, page)
        links[row["log"]] = f"{link_base}/{name}"
    return Views(links, refused)


def _remove_unlinked(folder: Path, views: Views) -> None:
    """Remove the pages of earlier reports from the views folder, once the new report is in
    place: every file named as a view that this report does not link to."""
    linked = {link.rsplit("/", 1)[-1] for link in views.links.values()}
    try:
        entries = list(folder.iterdir())
    except OSError:
        return  # no folder (no view written), or one that cannot be listed: nothing to tidy
    for entry in entries:
        if entry.name not in linked and VIEW_NAME.fullmatch(entry.name) and entry.is_file():
            with contextlib.suppress(OSError):
                entry.unlink()


def _view_command(row: Mapping[str, Any], options: Options) -> str:
    """The ``tlmpc view`` command that draws ``row``'s log as the batch read it."""
    words = ["tlmpc", "view", "--log", row["log"], "--mission", row["mission"]]
    if options.topic is not None:
        words += ["--topic", options.topic]
    if options.columns is not None:
        words += ["--columns", ",".join(options.columns)]
    if options.transform is not None:
        words += ["--transform", ",".join(repr(v) for v in options.transform)]
    if options.frame is not None:
        words += ["--frame", options.frame]
    return " ".join(shlex.quote(word) for word in words)


def render_report(
    rows: Sequence[Mapping[str, Any]],
    documents: Mapping[str, Mapping[str, Any]],
    *,
    group: str | None = None,
    views: Views | None = None,
    reading: Mapping[str, Options] | None = None,
) -> str:
    """The page for ``rows`` (the batch's records), ``documents`` the missions by path,
    ``reading`` each log's reading options (for the command that draws a log without a page)."""
    pattern = group_pattern(group)
    views = views or Views()
    reading = reading or {}
    root = _common_root([r["log"] for r in rows])
    places = {r["log"]: robot_and_day(r["log"], root, pattern) for r in rows}
    verdicts = Counter(r["verdict"] for r in rows)
    summary = " · ".join(
        f'<span class="{v}">{verdicts[v]} {v}</span>'
        for v in ("violated", "inconclusive", "satisfied", "error")
        if verdicts[v]
    )
    formulas = sorted({r["formula"] for r in rows if r.get("formula")})
    maps = [
        _heat_map(mission, documents[mission], [r for r in rows if r.get("mission") == mission])
        for mission in sorted(documents)
    ]
    table = []
    for row in rows:
        robot, day = places[row["log"]]
        first = row.get("first_violation") or {}
        link = views.links.get(row["log"])
        refused = views.refused.get(row["log"])
        if link is not None:
            view = f'<a href="{_href(link)}">view</a>'
        elif refused is not None:
            view = f"no view: {_e(refused.message)}" + (
                f"<br>{_e(refused.hint)}" if refused.hint else ""
            )
        elif row.get("mission"):
            command = _view_command(row, reading.get(row["log"], Options()))
            view = f'<span class="formula">{_e(command)}</span>'
        else:
            view = ""
        problem = _e(row["error"]["message"]) if row.get("error") else ""
        table.append(
            "<tr>"
            f'<td class="formula">{_e(row["log"])}</td><td>{_e(robot)}</td><td>{_e(day)}</td>'
            f"<td>{_verdict(row['verdict'])}{'<br>' + problem if problem else ''}</td>"
            f'<td class="formula">{_e(first.get("conjunct", ""))}</td>'
            f'<td class="n">{_number(first.get("t"))}</td>'
            f'<td class="n">{_number(first.get("x"))}</td>'
            f'<td class="n">{_number(first.get("y"))}</td>'
            f"<td>{view}</td></tr>"
        )
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta http-equiv="Content-Security-Policy" content="default-src \'none\'; '
        "style-src 'unsafe-inline'; img-src data:\">\n"
        f"<title>tlmpc fleet report</title>\n<style>{STYLE}</style>\n</head>\n<body>\n"
        f"<h1>Fleet report: {len(rows)} logs</h1>\n<p>{summary}</p>\n"
        + "".join(f'<p class="formula">{_e(f)}</p>' for f in formulas)
        + "<h2>Verdicts per robot and day</h2>\n"
        + _robots_by_day(rows, places)
        + "\n<h2>Violations per conjunct</h2>\n"
        + _conjuncts(rows)
        + "\n<h2>Where violations happen</h2>\n"
        + "".join(maps)
        + "\n<h2>Logs</h2>\n<table><tr><th>log</th><th>robot</th><th>day</th><th>verdict</th>"
        "<th>first violation</th><th>t (s from start)</th><th>x</th><th>y</th><th>view</th></tr>"
        + "".join(table)
        + "</table>\n</body>\n</html>\n"
    )


def write_report(
    path: Path, rows: Sequence[Mapping[str, Any]], jobs: Sequence[Job], *, group: str | None
) -> None:
    """Write the report at ``path`` and the logs' views in ``<path stem>.views/`` beside it."""
    documents = {job.mission: job.document for job in jobs if job.mission is not None}
    reading = {job.log: job.options for job in jobs}
    folder = views_folder(path)
    views = _views(rows, folder, folder.name, reading)
    page = render_report(rows, documents, group=group, views=views, reading=reading)
    write_atomically(path, page.encode("utf-8"))
    _remove_unlinked(folder, views)
