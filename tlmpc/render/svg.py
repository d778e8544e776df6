"""``plan.svg`` written directly from a :class:`~tlmpc.render.scene.Scene` (no plotting library).

The picture a compile always writes, so it must be cheap: a few string joins, no font
machinery.  Coordinates are mapped to pixels here, which gives every stroke a width on the
screen — a wall a micrometre thick or a door between two holes still shows as a line —
and lets the text and markers keep their size whatever the map's scale.  The legend and the
colour scale sit beside the map, never on it.  The same scene always gives the same bytes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from html import escape as _html_escape
from itertools import chain
from typing import TYPE_CHECKING

from tlmpc.render.layout import (
    FONT_PX,
    LABEL_HALO,
    LABEL_PX,
    PAD,
    SMALL_PX,
    TITLE_PX,
    Canvas,
    FigureLayout,
    baseline_offset,
    layout,
    shown,
)
from tlmpc.render.scene import Path, Point, Scene, viridis

if TYPE_CHECKING:
    from tlmpc.render.scene import FloatArray

_COLOUR_STEPS = 48  # the trajectory is drawn in this many colours along its length
_MIN_STEP_PX = 0.4  # consecutive samples closer than this on screen are merged


#: the colour of a counterstrategy play (an unrealizable reactive mission)
PLAY_COLOUR = "#7b2cbf"


def escape(text: str) -> str:
    """Text for an SVG element: XML-escaped, with control characters, noncharacters and lone
    surrogates (which XML 1.0 and UTF-8 do not allow at all), newlines and direction controls
    as visible escapes (:func:`~tlmpc.render.layout.shown`: the text the layout measured)."""
    return _html_escape(shown(text))


def _fmt(value: float) -> str:
    return f"{value:.1f}"


def _xy(canvas: Canvas, point: Point) -> str:
    x, y = canvas.pixel(point)
    return f"{x:.1f} {y:.1f}"


def _segments(canvas: Canvas, segments: FloatArray) -> str:
    """Path data of many line segments (rows ``x0, y0, x1, y1``), formatted in one pass."""
    pixels = segments.copy()
    pixels[:, 0::2] = canvas.left + (pixels[:, 0::2] - canvas.x0) * canvas.scale
    pixels[:, 1::2] = canvas.top + (canvas.y1 - pixels[:, 1::2]) * canvas.scale
    return ("M%.1f %.1fL%.1f %.1f" * len(pixels)) % tuple(pixels.ravel().tolist())


def _polygon_path(canvas: Canvas, polygon: Sequence[Point]) -> str:
    return "M" + "L".join(_xy(canvas, p) for p in polygon) + "Z"


#: From this many polygons on, their paths are formatted in one pass over a numpy array.
_BATCH_FROM = 64


def _polygon_paths(
    canvas: Canvas, polygons: Sequence[Sequence[Point]], points: FloatArray | None = None
) -> list[str]:
    """:func:`_polygon_path` of each polygon, the same text.

    Many polygons (maps with thousands of rooms) are mapped to pixels with numpy, by the
    same float operations as :func:`_xy`, and written with one ``%``-format (``%.1f``
    formats as ``:.1f`` does).  ``points``, when given, holds the polygons' points in order
    as rows ``x, y`` (the scene's own array: no second conversion).
    """
    if len(polygons) < _BATCH_FROM:
        return [_polygon_path(canvas, polygon) for polygon in polygons]
    import numpy as np

    if points is None:
        points = np.array(list(chain.from_iterable(polygons)), dtype=np.float64).reshape(-1, 2)
    pixels = np.empty_like(points)
    pixels[:, 0] = canvas.left + (points[:, 0] - canvas.x0) * canvas.scale
    pixels[:, 1] = canvas.top + (canvas.y1 - points[:, 1]) * canvas.scale
    # One template per ring length (most maps repeat a few: rooms are rectangles).
    templates: dict[int, str] = {}
    for polygon in polygons:
        if len(polygon) not in templates:
            templates[len(polygon)] = "M" + "L".join(["%.1f %.1f"] * len(polygon)) + "Z"
    template = "\n".join([templates[len(polygon)] for polygon in polygons])
    return (template % tuple(pixels.ravel().tolist())).split("\n")


def _polyline(canvas: Canvas, points: Sequence[Point]) -> str:
    return "M" + "L".join(_xy(canvas, p) for p in points)


def _decimated(canvas: Canvas, path: Path) -> list[tuple[float, float, float]]:
    """Pixel points ``(x, y, fraction)``, merging samples closer than a fraction of a pixel."""
    kept: list[tuple[float, float, float]] = []
    for point, fraction in zip(path.points, path.fractions, strict=True):
        x, y = canvas.pixel(point)
        if kept and math.hypot(x - kept[-1][0], y - kept[-1][1]) < _MIN_STEP_PX:
            continue
        kept.append((x, y, fraction))
    last_x, last_y = canvas.pixel(path.points[-1])
    if kept[-1][:2] != (last_x, last_y):
        kept.append((last_x, last_y, path.fractions[-1]))
    return kept


def _coloured_path(canvas: Canvas, path: Path, width: float) -> list[str]:
    """The path as polylines of ``_COLOUR_STEPS`` colours by arc length."""
    points = _decimated(canvas, path)
    if len(points) < 2:
        return []
    pieces: list[str] = []
    bucket = min(int(points[0][2] * _COLOUR_STEPS), _COLOUR_STEPS - 1)
    run = [points[0]]
    for point in points[1:]:
        run.append(point)
        b = min(int(point[2] * _COLOUR_STEPS), _COLOUR_STEPS - 1)
        if b != bucket:
            pieces.append(_run(run, bucket, width))
            run = [point]
            bucket = b
    if len(run) >= 2:
        pieces.append(_run(run, bucket, width))
    return pieces


def _run(run: Sequence[tuple[float, float, float]], bucket: int, width: float) -> str:
    d = "M" + "L".join(f"{_fmt(x)} {_fmt(y)}" for x, y, _ in run)
    colour = viridis((bucket + 0.5) / _COLOUR_STEPS)
    return f'<path d="{d}" stroke="{colour}" stroke-width="{width}"/>'


_LINE = '<path d="M{x} {cy}H{x2}" stroke="{colour}" stroke-width="{width}"{extra}/>'
_RECT = (
    '<rect x="{x}" y="{cy}" width="22" height="10" transform="translate(0,-5)" '
    'fill="{colour}" fill-opacity="{opacity}" stroke="{stroke}" stroke-width="{width}"/>'
)
#: The legend's swatch of each row kind: a template filled with the swatch's place.
_SWATCHES = {
    "hole": _RECT.replace("{colour}", "#9a9a9a")
    .replace("{opacity}", "1")
    .replace("{stroke}", "#000")
    .replace("{width}", "1.2"),
    "mesh": _LINE.replace("{colour}", "#b0b0b0").replace("{width}", "0.6").replace("{extra}", ""),
    "plan": _LINE.replace("{colour}", "#1f3b73").replace("{width}", "1").replace("{extra}", ""),
    "cycle": _LINE.replace("{colour}", "#c0392b")
    .replace("{width}", "1")
    .replace("{extra}", ' stroke-dasharray="4 3"'),
    "start": '<circle cx="{cx}" cy="{cy}" r="4" fill="#fff" stroke="#000" stroke-width="1.6"/>',
    "log": _LINE.replace("{colour}", "#e4007c").replace("{width}", "2").replace("{extra}", ""),
    "violation": '<path d="M{x} {cy}m6 -5l10 10m0 -10l-10 10" stroke="#d00" stroke-width="2.4" '
    'fill="none"/>',
}


def _legend(scene: Scene, figure: FigureLayout) -> list[str]:
    """The legend's swatches and texts, and the colour bar, as the layout places them."""
    out: list[str] = []
    region_colour = scene.regions[0].colour if scene.regions else "#000"
    for row in figure.legend:
        swatch = _SWATCHES.get(row.kind)
        if row.kind in ("region", "task-region"):
            emphasised = row.kind == "task-region"
            colour = "#1f1f1f" if emphasised else region_colour
            swatch = (
                _RECT.replace("{colour}", colour)
                .replace("{stroke}", colour)
                .replace("{opacity}", "0.8" if emphasised else "0.35")
                .replace("{width}", "1")
            )
        if swatch is not None:
            out.append(
                swatch.format(
                    x=_fmt(row.x), cx=_fmt(row.x + 11), cy=_fmt(row.y - 4), x2=_fmt(row.x + 22)
                )
            )
        x = row.x + 30 if swatch is not None else row.x
        size = "" if row.font_px == FONT_PX else f' font-size="{row.font_px:g}"'
        out.append(f'<text x="{_fmt(x)}" y="{_fmt(row.y)}"{size}>{escape(row.text)}</text>')
    bar = figure.colour_bar
    if bar is not None:
        stops = "".join(
            f'<stop offset="{_fmt(i / 10)}" stop-color="{viridis(i / 10)}"/>' for i in range(11)
        )
        out.append(
            f'<defs><linearGradient id="arc">{stops}</linearGradient></defs>'
            f'<rect x="{_fmt(bar.x0)}" y="{_fmt(bar.y0)}" width="{_fmt(bar.x1 - bar.x0)}" '
            f'height="{_fmt(bar.y1 - bar.y0)}" fill="url(#arc)"/>'
        )
        out.append(f'<text x="{_fmt(bar.x0)}" y="{_fmt(bar.y1 + 12)}">0</text>')
        out.append(
            f'<text x="{_fmt(bar.x1)}" y="{_fmt(bar.y1 + 12)}" text-anchor="end">'
            f"{escape(figure.colour_bar_end)}</text>"
        )
    return out


def render_svg(scene: Scene) -> bytes:
    """The SVG document of ``scene`` (UTF-8 bytes, deterministic)."""
    figure = layout(scene)
    canvas = figure.canvas
    width = figure.width
    height = figure.height
    parts: list[str] = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_fmt(width)}" '
        f'height="{_fmt(height)}" viewBox="0 0 {_fmt(width)} {_fmt(height)}" '
        f'font-family="DejaVu Sans, Arial, sans-serif" font-size="{FONT_PX:g}">',
        f"<title>{escape(scene.title)}</title>",
        '<rect width="100%" height="100%" fill="#fff"/>',
        f'<text x="{_fmt(canvas.left)}" y="{_fmt(PAD + 12)}" font-size="{TITLE_PX:g}">'
        f"{escape(figure.title)}</text>",
        '<defs><clipPath id="view">'
        f'<rect x="{_fmt(canvas.left)}" y="{_fmt(canvas.top)}" width="{_fmt(canvas.width)}" '
        f'height="{_fmt(canvas.height)}"/></clipPath></defs>',
        '<g clip-path="url(#view)" fill="none" stroke-linejoin="round" stroke-linecap="round">',
        f'<path d="{_polygon_path(canvas, scene.boundary)}" fill="#fff"/>',
    ]
    if scene.components:
        # Pieces of free space may lie inside holes: paint the holes first, then the pieces
        # and their own holes over them, all below the regions and the mesh.
        for rings, colour in (
            (scene.holes, "#9a9a9a"),
            (scene.components, "#fff"),
            (scene.component_holes, "#9a9a9a"),
        ):
            if rings:
                d = "".join(_polygon_path(canvas, ring) for ring in rings)
                parts.append(f'<path d="{d}" fill="{colour}" stroke="#000" stroke-width="1.2"/>')
    by_colour: dict[tuple[str, bool], list[str]] = {}
    region_paths = _polygon_paths(
        canvas, [region.polygon for region in scene.regions], scene.region_points
    )
    for region, path in zip(scene.regions, region_paths, strict=True):
        emphasised = scene.emphasise_task_regions and region.named_by_task
        key = ("#1f1f1f" if emphasised else region.colour, emphasised)
        by_colour.setdefault(key, []).append(path)
    for (colour, emphasised), paths in sorted(by_colour.items()):
        opacity = "0.8" if emphasised else "0.3"
        parts.append(
            f'<path d="{"".join(paths)}" fill="{colour}" fill-opacity="{opacity}" '
            f'stroke="{colour}" stroke-width="0.8"/>'
        )
    if len(scene.mesh_edges):
        d = _segments(canvas, scene.mesh_edges)
        parts.append(f'<path d="{d}" stroke="#b0b0b0" stroke-width="0.4"/>')
    if scene.holes and not scene.components:
        d = "".join(_polygon_path(canvas, hole) for hole in scene.holes)
        # The stroke is in pixels: a hole thinner than a pixel still shows as a 1.2 px wall.
        parts.append(f'<path d="{d}" fill="#9a9a9a" stroke="#000" stroke-width="1.2"/>')
    parts.append(
        f'<path d="{_polygon_path(canvas, scene.boundary)}" stroke="#000" stroke-width="1.5"/>'
    )
    if len(scene.plan_prefix) >= 2:
        parts.append(
            f'<path d="{_polyline(canvas, scene.plan_prefix)}" stroke="#1f3b73" '
            'stroke-width="1" stroke-opacity="0.7"/>'
        )
    if len(scene.plan_cycle) >= 2 and not scene.plan_stays:
        parts.append(
            f'<path d="{_polyline(canvas, scene.plan_cycle)}" stroke="#c0392b" '
            'stroke-width="1" stroke-dasharray="4 3"/>'
        )
    if scene.trajectory is not None:
        parts.extend(_coloured_path(canvas, scene.trajectory, 2.0))
    if scene.log is not None:
        points = [(x, y) for x, y, _ in _decimated(canvas, scene.log)]
        d = "M" + "L".join(f"{_fmt(x)} {_fmt(y)}" for x, y in points)
        parts.append(f'<path d="{d}" stroke="#e4007c" stroke-width="1.6" stroke-opacity="0.85"/>')
    if scene.start is not None:
        # Small and hollow, under the labels: it marks the start without hiding a name.
        sx, sy = canvas.pixel(scene.start)
        parts.append(
            f'<circle cx="{_fmt(sx)}" cy="{_fmt(sy)}" r="4" fill="#fff" stroke="#000" '
            'stroke-width="1.6"/>'
        )
    if len(scene.play_route) >= 2:
        parts.append(
            f'<path d="{_polyline(canvas, scene.play_route)}" stroke="{PLAY_COLOUR}" '
            'stroke-width="2" stroke-dasharray="6 3" fill="none"/>'
        )
    for mark in scene.play:
        px, py = canvas.pixel(mark.position)
        text = escape(mark.text)
        parts.append(
            f'<circle cx="{_fmt(px)}" cy="{_fmt(py)}" r="5" fill="{PLAY_COLOUR}" stroke="#fff"/>'
            f'<text x="{_fmt(px + 8)}" y="{_fmt(py + 4)}" stroke="#fff" stroke-width="3">'
            f'{text}</text><text x="{_fmt(px + 8)}" y="{_fmt(py + 4)}" fill="{PLAY_COLOUR}">'
            f"{text}</text>"
        )
    for number, violation in enumerate(scene.violations, start=1):
        vx, vy = canvas.pixel(violation.position)
        parts.append(
            f'<path d="M{_fmt(vx - 6)} {_fmt(vy - 6)}l12 12m0 -12l-12 12" stroke="#d00" '
            'stroke-width="2.4"/>'
            f'<text x="{_fmt(vx + 8)}" y="{_fmt(vy - 6)}" stroke="#fff" stroke-width="3">'
            f'{number}</text><text x="{_fmt(vx + 8)}" y="{_fmt(vy - 6)}" fill="#d00">'
            f"{number}</text>"
        )
    if figure.labels:
        # A white halo under each name (drawn first: not every renderer knows paint-order).
        body = "".join(
            f'<text x="{_fmt(label.x)}" y="{_fmt(label.y + baseline_offset(label.font_px))}">'
            f"{escape(label.text)}</text>"
            for label in figure.labels
        )
        parts.append(
            f'<g class="labels" text-anchor="middle" font-size="{LABEL_PX:g}">'
            f'<g stroke="#fff" stroke-width="{2 * LABEL_HALO:g}" fill="#fff" '
            f'stroke-opacity="0.85">{body}</g><g fill="#000">{body}</g></g>'
        )
    parts.append("</g>")
    parts.append(
        f'<text x="{_fmt(canvas.left)}" y="{_fmt(figure.extent_y)}" '
        f'font-size="{SMALL_PX:g}" fill="#555">{escape(figure.extent_text)}</text>'
    )
    parts.extend(_legend(scene, figure))
    parts.append("</svg>\n")
    return "\n".join(parts).encode("utf-8")
