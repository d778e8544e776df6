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

from tlmpc.base.errors import printable
from tlmpc.render.scene import Path, Point, Region, Scene, viridis

if TYPE_CHECKING:
    from tlmpc.render.scene import FloatArray

_MAX_WIDTH = 900.0  # pixels for the map's width ...
_MAX_HEIGHT = 700.0  # ... and height; the map keeps its aspect ratio within both
_MIN_HEIGHT = 40.0  # a very wide corridor still gets a visible strip
_PAD = 14.0
_TITLE = 26.0
_LEGEND_WIDTH = 230.0
_COLOUR_STEPS = 48  # the trajectory is drawn in this many colours along its length
_MIN_STEP_PX = 0.4  # consecutive samples closer than this on screen are merged


def escape(text: str) -> str:
    """Text for an SVG element: XML-escaped, with control characters (which XML 1.0 does not
    allow at all), newlines and direction controls as visible escapes."""
    return _html_escape(printable(text, keep=""))


def _fmt(value: float) -> str:
    return f"{value:.1f}"


class _Canvas:
    """World-to-pixel mapping of the scene's view (y upwards in the world, down on screen)."""

    def __init__(self, view: tuple[float, float, float, float]) -> None:
        x0, y0, x1, y1 = view
        width = max(x1 - x0, 1e-12)
        height = max(y1 - y0, 1e-12)
        self.scale = min(_MAX_WIDTH / width, _MAX_HEIGHT / height)
        if height * self.scale < _MIN_HEIGHT:
            self.scale = min(_MIN_HEIGHT / height, 4.0 * _MAX_WIDTH / width)
        self.x0 = x0
        self.y1 = y1
        self.left = _PAD
        self.top = _PAD + _TITLE
        self.width = width * self.scale
        self.height = height * self.scale

    def xy(self, point: Point) -> str:
        x = self.left + (point[0] - self.x0) * self.scale
        y = self.top + (self.y1 - point[1]) * self.scale
        return f"{x:.1f} {y:.1f}"

    def pixel(self, point: Point) -> tuple[float, float]:
        return (
            self.left + (point[0] - self.x0) * self.scale,
            self.top + (self.y1 - point[1]) * self.scale,
        )


def _segments(canvas: _Canvas, segments: FloatArray) -> str:
    """Path data of many line segments (rows ``x0, y0, x1, y1``), formatted in one pass."""
    pixels = segments.copy()
    pixels[:, 0::2] = canvas.left + (pixels[:, 0::2] - canvas.x0) * canvas.scale
    pixels[:, 1::2] = canvas.top + (canvas.y1 - pixels[:, 1::2]) * canvas.scale
    return ("M%.1f %.1fL%.1f %.1f" * len(pixels)) % tuple(pixels.ravel().tolist())


def _label_position(canvas: _Canvas, region: Region) -> tuple[float, float, str]:
    """Where a region's name goes: on it when it fits, else just above it."""
    x, y = canvas.pixel(region.label_at)
    xs = [canvas.pixel(p)[0] for p in region.polygon]
    ys = [canvas.pixel(p)[1] for p in region.polygon]
    if max(xs) - min(xs) >= 6.2 * len(region.name) and max(ys) - min(ys) >= 12:
        return x, y, "central"
    return x, min(ys) - 2.0, "text-after-edge"


def _polygon_path(canvas: _Canvas, polygon: Sequence[Point]) -> str:
    return "M" + "L".join(canvas.xy(p) for p in polygon) + "Z"


#: From this many polygons on, their paths are formatted in one pass over a numpy array.
_BATCH_FROM = 64


def _polygon_paths(
    canvas: _Canvas, polygons: Sequence[Sequence[Point]], points: FloatArray | None = None
) -> list[str]:
    """:func:`_polygon_path` of each polygon, the same text.

    Many polygons (maps with thousands of rooms) are mapped to pixels with numpy, by the
    same float operations as :meth:`_Canvas.xy`, and written with one ``%``-format (``%.1f``
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


def _polyline(canvas: _Canvas, points: Sequence[Point]) -> str:
    return "M" + "L".join(canvas.xy(p) for p in points)


def _decimated(canvas: _Canvas, path: Path) -> list[tuple[float, float, float]]:
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


def _coloured_path(canvas: _Canvas, path: Path, width: float) -> list[str]:
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


def _wrap(text: str, width: int) -> list[str]:
    lines: list[str] = []
    current = ""
    for word in text.split():
        if current and len(current) + 1 + len(word) > width:
            lines.append(current)
            current = word
        else:
            current = f"{current} {word}".strip()
    if current:
        lines.append(current)
    return lines[:4]


def _legend(scene: Scene, x: float, y: float) -> tuple[list[str], float]:
    """Legend entries from the top-left corner ``(x, y)``; returns them and their height."""
    out: list[str] = []
    row = y

    def entry(swatch: str, label: str) -> None:
        nonlocal row
        out.append(swatch.format(x=_fmt(x), cx=_fmt(x + 11), cy=_fmt(row), x2=_fmt(x + 22)))
        out.append(f'<text x="{_fmt(x + 30)}" y="{_fmt(row + 4)}">{escape(label)}</text>')
        row += 18

    line = '<path d="M{x} {cy}H{x2}" stroke="{colour}" stroke-width="{w}"{extra}/>'
    if scene.holes or scene.component_holes:
        entry(
            '<rect x="{x}" y="{cy}" width="22" height="10" transform="translate(0,-5)" '
            'fill="#9a9a9a" stroke="#000" stroke-width="1.2"/>',
            "obstacle (hole)",
        )
    if scene.regions:
        colour = "#1f1f1f" if scene.emphasise_task_regions else scene.regions[0].colour
        label = "task region" if scene.emphasise_task_regions else "region"
        opacity = "0.8" if scene.emphasise_task_regions else "0.35"
        entry(
            '<rect x="{x}" y="{cy}" width="22" height="10" transform="translate(0,-5)" '
            f'fill="{colour}" fill-opacity="{opacity}" stroke="{colour}"/>',
            label,
        )
    if len(scene.mesh_edges):
        entry(line.format_map(_Keep(colour="#b0b0b0", w="0.6", extra="")), "triangulation")
    if len(scene.plan_prefix) >= 2:
        entry(line.format_map(_Keep(colour="#1f3b73", w="1", extra="")), "plan (triangles)")
    if len(scene.plan_cycle) >= 2 and not scene.plan_stays:
        entry(
            line.format_map(_Keep(colour="#c0392b", w="1", extra=' stroke-dasharray="4 3"')),
            "plan cycle (repeats)",
        )
    if scene.start is not None:
        entry(
            '<circle cx="{cx}" cy="{cy}" r="4" fill="#fff" stroke="#000" stroke-width="1.6"/>',
            "start",
        )
    if scene.log is not None:
        entry(line.format_map(_Keep(colour="#e4007c", w="2", extra="")), "recorded log")
    for number, violation in enumerate(scene.violations, start=1):
        entry(_cross_swatch(), f"violation {number}")
        for text in _wrap(violation.message, 34):
            out.append(
                f'<text x="{_fmt(x + 30)}" y="{_fmt(row)}" font-size="9">{escape(text)}</text>'
            )
            row += 12
    if scene.trajectory is not None:
        row += 4
        out.append(f'<text x="{_fmt(x)}" y="{_fmt(row)}">trajectory, coloured by</text>')
        out.append(f'<text x="{_fmt(x)}" y="{_fmt(row + 13)}">distance travelled</text>')
        row += 22
        stops = "".join(
            f'<stop offset="{_fmt(i / 10)}" stop-color="{viridis(i / 10)}"/>' for i in range(11)
        )
        out.append(
            f'<defs><linearGradient id="arc">{stops}</linearGradient></defs>'
            f'<rect x="{_fmt(x)}" y="{_fmt(row)}" width="150" height="10" fill="url(#arc)"/>'
        )
        row += 22
        out.append(f'<text x="{_fmt(x)}" y="{_fmt(row)}">0</text>')
        out.append(
            f'<text x="{_fmt(x + 150)}" y="{_fmt(row)}" text-anchor="end">'
            f"{scene.trajectory.length:.4g}</text>"
        )
        row += 6
    if scene.regions_omitted:
        row += 12
        out.append(
            f'<text x="{_fmt(x)}" y="{_fmt(row)}" font-size="9">{scene.regions_omitted:,} '
            "other regions not drawn</text>"
        )
    if scene.mesh_omitted:
        row += 12
        out.append(
            f'<text x="{_fmt(x)}" y="{_fmt(row)}" font-size="9">mesh of '
            f"{scene.mesh_omitted:,} triangles not drawn</text>"
        )
        row += 12
        out.append(f'<text x="{_fmt(x)}" y="{_fmt(row)}" font-size="9">(zoom in to see it)</text>')
    return out, row - y


class _Keep(dict[str, str]):
    """``format_map`` helper that leaves the legend's own placeholders in place."""

    def __missing__(self, key: str) -> str:
        return "{" + key + "}"


def _cross_swatch() -> str:
    return (
        '<path d="M{x} {cy}m6 -5l10 10m0 -10l-10 10" stroke="#d00" stroke-width="2.4" fill="none"/>'
    )


def render_svg(scene: Scene) -> bytes:
    """The SVG document of ``scene`` (UTF-8 bytes, deterministic)."""
    canvas = _Canvas(scene.view)
    map_right = canvas.left + canvas.width
    legend_x = map_right + 18
    legend, legend_height = _legend(scene, legend_x, canvas.top + 8)
    width = legend_x + _LEGEND_WIDTH
    height = max(canvas.top + canvas.height + _PAD, canvas.top + legend_height + 2 * _PAD)
    parts: list[str] = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_fmt(width)}" '
        f'height="{_fmt(height)}" viewBox="0 0 {_fmt(width)} {_fmt(height)}" '
        'font-family="DejaVu Sans, Arial, sans-serif" font-size="11">',
        f"<title>{escape(scene.title)}</title>",
        '<rect width="100%" height="100%" fill="#fff"/>',
        f'<text x="{_fmt(canvas.left)}" y="{_fmt(_PAD + 12)}" font-size="14">'
        f"{escape(scene.title)}</text>",
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
    for number, violation in enumerate(scene.violations, start=1):
        vx, vy = canvas.pixel(violation.position)
        parts.append(
            f'<path d="M{_fmt(vx - 6)} {_fmt(vy - 6)}l12 12m0 -12l-12 12" stroke="#d00" '
            'stroke-width="2.4"/>'
            f'<text x="{_fmt(vx + 8)}" y="{_fmt(vy - 6)}" stroke="#fff" stroke-width="3">'
            f'{number}</text><text x="{_fmt(vx + 8)}" y="{_fmt(vy - 6)}" fill="#d00">'
            f"{number}</text>"
        )
    labels = [r for r in scene.regions if r.labelled]
    if labels:
        # A white halo under each name (drawn first: not every renderer knows paint-order).
        texts = []
        for region in labels:
            lx, ly, baseline = _label_position(canvas, region)
            texts.append(
                f'<text x="{_fmt(lx)}" y="{_fmt(ly)}" dominant-baseline="{baseline}">'
                f"{escape(region.name)}</text>"
            )
        body = "".join(texts)
        parts.append(
            '<g text-anchor="middle" font-size="10">'
            f'<g stroke="#fff" stroke-width="3" fill="#fff" stroke-opacity="0.85">{body}</g>'
            f'<g fill="#000">{body}</g></g>'
        )
    parts.append("</g>")
    x0, y0, x1, y1 = scene.view
    parts.append(
        f'<text x="{_fmt(canvas.left)}" y="{_fmt(canvas.top + canvas.height + 11)}" '
        f'font-size="9" fill="#555">x {x0:.4g} … {x1:.4g}, y {y0:.4g} … {y1:.4g}</text>'
    )
    parts.extend(legend)
    parts.append("</svg>\n")
    return "\n".join(parts).encode("utf-8")
