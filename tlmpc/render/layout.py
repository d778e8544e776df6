"""Where everything of a figure goes, in pixels: computed once, drawn by every renderer.

A :class:`FigureLayout` maps a :class:`~tlmpc.render.scene.Scene` onto a page measured in
figure pixels: the map's rectangle and its world-to-pixel scale, the region names placed so
that no two overlap and none leaves the map, the legend's rows beside the map and the colour
bar.  The SVG writer draws it at one figure pixel per SVG pixel, the PNG renderer at
:data:`PNG_PIXELS_PER_FIGURE_PIXEL` device pixels per figure pixel; both draw the same rows,
names, sizes and positions, so the two pictures agree (a test compares them).

Text widths come from the advance widths of DejaVu Sans (the font both pictures name first),
so a name's box is known without a font library; a character outside ASCII counts as the
font's widest glyph, so a box is never narrower than the text drawn in it.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from itertools import accumulate

from tlmpc.base.errors import printable
from tlmpc.render.scene import Point, Region, Scene, label_priority

#: Figure pixels for the map's width and height at most (it keeps its aspect ratio).
MAX_MAP_WIDTH = 900.0
MAX_MAP_HEIGHT = 700.0
MIN_MAP_HEIGHT = 40.0  # a very wide corridor still gets a visible strip
PAD = 14.0
TITLE_HEIGHT = 26.0
LEGEND_GAP = 18.0
LEGEND_WIDTH = 230.0
#: Font sizes in figure pixels.
FONT_PX = 11.0
TITLE_PX = 14.0
SMALL_PX = 9.0
LABEL_PX = 10.0
#: The halo around a name (figure pixels), and the free margin kept between two names' boxes.
LABEL_HALO = 1.5
LABEL_GAP = 1.0
#: A legend text line wraps at this width (figure pixels).
LEGEND_TEXT_WIDTH = LEGEND_WIDTH - 36.0
#: The PNG is drawn at 150 dpi with 100 figure pixels per inch.
PNG_PIXELS_PER_FIGURE_PIXEL = 1.5

#: Advance widths of DejaVu Sans, ASCII 32..126, in font units (its hmtx table, 2048 per em).
_ADVANCE = (
    651, 821, 942, 1716, 1303, 1946, 1597, 563, 799, 799, 1024, 1716, 651, 739, 651, 690,
    1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 690, 690, 1716, 1716, 1716, 1087,
    2048, 1401, 1405, 1430, 1577, 1294, 1178, 1587, 1540, 604, 604, 1343, 1141, 1767, 1532, 1612,
    1235, 1612, 1423, 1300, 1251, 1499, 1401, 2025, 1403, 1251, 1403, 799, 690, 799, 1716, 1024,
    1024, 1255, 1300, 1126, 1300, 1260, 721, 1300, 1298, 569, 569, 1186, 569, 1995, 1298, 1253,
    1300, 1300, 842, 1067, 803, 1298, 1212, 1675, 1212, 1212, 1075, 1303, 690, 1303, 1716,
)  # fmt: skip
_UNITS_PER_EM = 2048
_MAX_ADVANCE = 3838  # the widest glyph of DejaVu Sans (its hhea advanceWidthMax)
#: Ascent plus descent of DejaVu Sans (em): the height of a line's ink box.
_LINE_EM = 1.164
_ASCENT_EM = 0.928


def _advances(text: str) -> list[int]:
    """The advance width of each character of ``text``, in font units."""
    return [_ADVANCE[ord(c) - 32] if 32 <= ord(c) < 127 else _MAX_ADVANCE for c in text]


def shown(text: str) -> str:
    """``text`` as every picture draws it: on one line, with control, direction and other
    unsafe characters as visible escapes (:func:`~tlmpc.base.errors.printable`).  The layout
    measures and wraps this text, so what is drawn is what was measured."""
    return printable(text, keep="")


def text_width(text: str, font_px: float) -> float:
    """The width of ``text`` in DejaVu Sans at ``font_px`` (at most: a non-ASCII character
    counts as the widest glyph)."""
    return sum(_advances(text)) * font_px / _UNITS_PER_EM


def text_height(font_px: float) -> float:
    """The height of one line of text at ``font_px``."""
    return _LINE_EM * font_px


def baseline_offset(font_px: float) -> float:
    """From the middle of a line's ink box down to its baseline."""
    return (_ASCENT_EM - _LINE_EM / 2) * font_px


@dataclass(frozen=True, slots=True)
class Canvas:
    """The map's rectangle on the figure and its world-to-pixel mapping (y flips)."""

    scale: float  # figure pixels per world unit, the same along x and y
    x0: float  # world x at the left edge
    y1: float  # world y at the top edge
    left: float
    top: float
    width: float
    height: float

    @classmethod
    def of(cls, view: tuple[float, float, float, float]) -> Canvas:
        """The canvas of the world window ``view`` = (x0, y0, x1, y1)."""
        x0, y0, x1, y1 = view
        width = max(x1 - x0, 1e-12)
        height = max(y1 - y0, 1e-12)
        scale = min(MAX_MAP_WIDTH / width, MAX_MAP_HEIGHT / height)
        if height * scale < MIN_MAP_HEIGHT:
            scale = min(MIN_MAP_HEIGHT / height, 4.0 * MAX_MAP_WIDTH / width)
        return cls(
            scale=scale,
            x0=x0,
            y1=y1,
            left=PAD,
            top=PAD + TITLE_HEIGHT,
            width=width * scale,
            height=height * scale,
        )

    def pixel(self, point: Point) -> tuple[float, float]:
        """The figure pixel of a world point."""
        return (
            self.left + (point[0] - self.x0) * self.scale,
            self.top + (self.y1 - point[1]) * self.scale,
        )

    def world(self, x: float, y: float) -> Point:
        """The world point of a figure pixel (the inverse of :meth:`pixel`)."""
        return (self.x0 + (x - self.left) / self.scale, self.y1 - (y - self.top) / self.scale)


@dataclass(frozen=True, slots=True)
class Box:
    """An axis-aligned rectangle in figure pixels."""

    x0: float
    y0: float
    x1: float
    y1: float

    def overlaps(self, other: Box) -> bool:
        """Whether the two boxes share interior points."""
        return (
            self.x0 < other.x1 and other.x0 < self.x1 and self.y0 < other.y1 and other.y0 < self.y1
        )

    def grown(self, margin: float) -> Box:
        """The box with ``margin`` added on every side."""
        return Box(self.x0 - margin, self.y0 - margin, self.x1 + margin, self.y1 + margin)

    def within(self, other: Box) -> bool:
        """Whether the box lies inside ``other``."""
        return (
            self.x0 >= other.x0
            and self.y0 >= other.y0
            and self.x1 <= other.x1
            and self.y1 <= other.y1
        )


@dataclass(frozen=True, slots=True)
class Label:
    """A region's name, centred on ``(x, y)`` (figure pixels), ``box`` around its ink."""

    name: str
    text: str  # the name as drawn and measured (:func:`shown`)
    x: float
    y: float
    font_px: float
    box: Box
    on_region: bool  # placed over its region (else beside it)


@dataclass(frozen=True, slots=True)
class LegendRow:
    """One row of the legend: a swatch of ``kind`` (or none) and its text, from ``y`` down.

    ``y`` is the text's baseline; a swatch is centred 4 pixels above it.
    """

    kind: str  # hole, region, task-region, mesh, plan, cycle, start, log, violation, text
    text: str  # as drawn (:func:`shown`)
    x: float
    y: float
    font_px: float


@dataclass(frozen=True, slots=True)
class FigureLayout:
    """The whole figure in figure pixels."""

    width: float
    height: float
    canvas: Canvas
    title: str  # as drawn (:func:`shown`), cut to one line
    labels: tuple[Label, ...]
    labels_hidden: tuple[str, ...]  # names with no free room on the map
    legend: tuple[LegendRow, ...]
    colour_bar: Box | None  # the trajectory's arc-length scale
    colour_bar_end: str  # the length written at the bar's right end
    extent_text: str  # "x … , y …" under the map
    extent_y: float


def _priority(region: Region) -> tuple[int, float, str]:
    return label_priority(region.name, region.polygon, region.named_by_task)


def _centred(x: float, y: float, width: float, height: float) -> Box:
    return Box(x - width / 2, y - height / 2, x + width / 2, y + height / 2)


def place_labels(
    regions: Sequence[Region],
    canvas: Canvas,
    obstacles: Sequence[Box] = (),
    *,
    font_px: float = LABEL_PX,
) -> tuple[tuple[Label, ...], tuple[str, ...]]:
    """Names placed greedily without overlap: task regions first, then larger ones first.

    Each name tries its region's label point, then just above, below, right and left of the
    region's box, then further above and below; it takes the first spot that lies on the map
    and meets no placed name and no ``obstacles`` (markers), all grown by their halo.  A name
    with no free spot is not drawn and returned among the hidden.
    """
    area = Box(canvas.left, canvas.top, canvas.left + canvas.width, canvas.top + canvas.height)
    taken = [b.grown(LABEL_GAP) for b in obstacles]
    placed: list[Label] = []
    hidden: list[str] = []
    height = text_height(font_px)
    for region in sorted((r for r in regions if r.labelled), key=_priority):
        text = shown(region.name)
        width = text_width(text, font_px)
        pixels = [canvas.pixel(p) for p in region.polygon]
        left = min(p[0] for p in pixels)
        right = max(p[0] for p in pixels)
        top = min(p[1] for p in pixels)
        bottom = max(p[1] for p in pixels)
        ax, ay = canvas.pixel(region.label_at)
        middle = (left + right) / 2
        step = height + 2 * LABEL_HALO
        spots = [
            (ax, ay, True),
            (middle, top - step / 2, False),
            (middle, bottom + step / 2, False),
            (right + LABEL_HALO + width / 2 + 2, (top + bottom) / 2, False),
            (left - LABEL_HALO - width / 2 - 2, (top + bottom) / 2, False),
        ]
        for k in (1, 2):
            spots.append((middle, top - step / 2 - k * step, False))
            spots.append((middle, bottom + step / 2 + k * step, False))
        for x, y, on_region in spots:
            box = _centred(x, y, width, height)
            halo = box.grown(LABEL_HALO)
            if not halo.within(area) or any(halo.overlaps(other) for other in taken):
                continue
            taken.append(halo.grown(LABEL_GAP))
            placed.append(Label(region.name, text, x, y, font_px, box, on_region))
            break
        else:
            hidden.append(region.name)
    placed.sort(key=lambda label: label.name)
    return tuple(placed), tuple(sorted(hidden))


def _pieces(word: str, font_px: float, width: float) -> Iterator[str]:
    """``word`` cut into pieces no wider than ``width`` pixels, each as long as fits (a piece
    of one character may be wider); a word that fits is its only piece.

    The widths come from running sums of the characters' advances, and each cut point is
    found by bisection, so a long word costs time linear in its length (measuring every
    prefix anew would be cubic).  A prefix's width is computed exactly as :func:`text_width`
    computes it (an integer sum of advances, scaled), so the pieces are the same.
    """
    ends = list(accumulate(_advances(word), initial=0))
    start, size = 0, len(word)

    def too_wide(end: int) -> bool:
        return (ends[end] - ends[start]) * font_px / _UNITS_PER_EM > width

    while too_wide(size) and size - start > 1:
        # the longest prefix of at least 2 characters (and not all) that fits, else 1
        low, high = 1, size - start - 1
        while low < high:
            middle = (low + high + 1) // 2
            if too_wide(start + middle):
                high = middle - 1
            else:
                low = middle
        yield word[start : start + low]
        start += low
    yield word[start:]


def wrap(text: str, font_px: float, width: float, lines: int = 4) -> list[str]:
    """``text`` broken on spaces into at most ``lines`` lines no wider than ``width`` pixels
    (a word longer than a line is cut); a cut tail ends in an ellipsis.

    Only the first ``lines`` + 1 lines are ever built, so a very long text costs little more
    than splitting it.
    """
    out: list[str] = []
    current = ""
    for word in text.split():
        for piece in _pieces(word, font_px, width):
            candidate = f"{current} {piece}" if current else piece
            if current and text_width(candidate, font_px) > width:
                out.append(current)
                current = piece
            else:
                current = candidate
            if len(out) > lines:
                break
        if len(out) > lines:
            break
    if current:
        out.append(current)
    if len(out) > lines:
        out = out[:lines]
        last = out[-1]
        while last and text_width(last + " …", font_px) > width:
            last = last[:-1]
        out[-1] = last.rstrip() + " …"
    return out


def _legend(
    scene: Scene, x: float, y: float, hidden: Sequence[str]
) -> tuple[list[LegendRow], Box | None]:
    rows: list[LegendRow] = []
    row = y

    def add(kind: str, text: str, size: float = FONT_PX, step: float = 18.0) -> None:
        nonlocal row
        rows.append(LegendRow(kind, text, x, row + 4, size))
        row += step

    if scene.holes or scene.component_holes:
        add("hole", "obstacle (hole)")
    if scene.regions:
        add(
            *(
                ("task-region", "task region")
                if scene.emphasise_task_regions
                else ("region", "region")
            )
        )
    if len(scene.mesh_edges):
        add("mesh", "triangulation")
    if len(scene.plan_prefix) >= 2:
        add("plan", "plan (triangles)")
    if len(scene.plan_cycle) >= 2 and not scene.plan_stays:
        add("cycle", "plan cycle (repeats)")
    if scene.start is not None:
        add("start", "start")
    if scene.log is not None:
        add("log", "recorded log")
    for number, violation in enumerate(scene.violations, start=1):
        add("violation", f"violation {number}")
        for text in wrap(shown(violation.message), SMALL_PX, LEGEND_TEXT_WIDTH):
            rows.append(LegendRow("text", text, x + 30, row, SMALL_PX))
            row += 12
    bar = None
    if scene.trajectory is not None:
        row += 4
        rows.append(LegendRow("heading", "trajectory, coloured by", x, row, FONT_PX))
        rows.append(LegendRow("heading", "distance travelled", x, row + 13, FONT_PX))
        row += 22
        bar = Box(x, row, x + 150, row + 10)
        row += 28
    if hidden:
        row += 12
        text = shown(f"not named (no room): {', '.join(hidden)}")
        for line in wrap(text, SMALL_PX, LEGEND_WIDTH - 6):
            rows.append(LegendRow("note", line, x, row, SMALL_PX))
            row += 12
        row -= 12
    notes = []
    if scene.regions_omitted:
        notes.append(f"{scene.regions_omitted:,} other regions not drawn")
    if scene.mesh_omitted:
        notes.append(f"mesh of {scene.mesh_omitted:,} triangles not drawn")
        notes.append("(zoom in to see it)")
    for note in notes:
        row += 12
        rows.append(LegendRow("note", note, x, row, SMALL_PX))
    return rows, bar


def layout(scene: Scene) -> FigureLayout:
    """The figure of ``scene``: map, names, legend and colour bar, in figure pixels."""
    canvas = Canvas.of(scene.view)
    markers: list[Box] = []
    if scene.start is not None:
        sx, sy = canvas.pixel(scene.start)
        markers.append(_centred(sx, sy, 10, 10))
    for violation in scene.violations:
        vx, vy = canvas.pixel(violation.position)
        markers.append(Box(vx - 7, vy - 18, vx + 20, vy + 7))  # the cross and its number
    labels, hidden = place_labels(scene.regions, canvas, markers)
    legend_x = canvas.left + canvas.width + LEGEND_GAP
    rows, bar = _legend(scene, legend_x, canvas.top + 8, hidden)
    legend_bottom = max([r.y + 4 for r in rows] + [bar.y1 + 20 if bar else 0.0])
    extent_y = canvas.top + canvas.height + 11
    height = max(extent_y + PAD, legend_bottom + PAD)
    x0, y0, x1, y1 = scene.view
    width = legend_x + LEGEND_WIDTH
    # escaped first: the title is measured as it is drawn
    title = wrap(shown(scene.title), TITLE_PX, width - 2 * PAD, lines=1)[0] if scene.title else ""
    return FigureLayout(
        width=width,
        height=math.ceil(height),
        canvas=canvas,
        title=title,
        labels=labels,
        labels_hidden=hidden,
        legend=tuple(rows),
        colour_bar=bar,
        colour_bar_end=f"{scene.trajectory.length:.4g}" if scene.trajectory is not None else "",
        extent_text=f"x {x0:.4g} … {x1:.4g}, y {y0:.4g} … {y1:.4g}",
        extent_y=extent_y,
    )
