"""Figures of a compiled mission, drawn from its artifacts alone (headless, reproducible).

Both pictures draw the same :class:`~tlmpc.render.scene.Scene`: the workspace, holes, regions
with their names, the triangulation, the discrete plan, the simulated trajectory coloured by
distance travelled, the start, and optionally a recorded log and its violations.

- :func:`render_svg` writes ``plan.svg`` directly (no plotting library): cheap enough that
  every compile draws it.
- :func:`render_png` draws ``plan.png`` with matplotlib (imported only here), on request.

The same artifacts always give the same bytes: no timestamps, no software tag.
"""

from __future__ import annotations

import contextlib
import io
import itertools
from collections.abc import Iterator, Mapping, Sequence
from typing import Any

from tlmpc.base.extras import require
from tlmpc.render.layout import (
    FONT_PX,
    LABEL_HALO,
    PAD,
    SMALL_PX,
    TITLE_PX,
    FigureLayout,
    baseline_offset,
    layout,
    shown,
)
from tlmpc.render.scene import Scene, build_scene, viridis
from tlmpc.render.svg import PLAY_COLOUR

View = tuple[float, float, float, float]


def render_svg(
    artifacts: Mapping[str, Any],
    *,
    zoom: View | None = None,
    log: Sequence[Sequence[float]] | None = None,
    verdict: Mapping[str, Any] | None = None,
) -> bytes:
    """``plan.svg`` of a compile output's artifacts (see :func:`.scene.build_scene`)."""
    from tlmpc.render.svg import render_svg as draw

    return draw(build_scene(artifacts, zoom=zoom, log=log, verdict=verdict))


#: Points per figure pixel: the PNG has 100 figure pixels per inch (and 150 dpi).
_PT = 0.72


def render_png(
    artifacts: Mapping[str, Any],
    *,
    zoom: View | None = None,
    log: Sequence[Sequence[float]] | None = None,
    verdict: Mapping[str, Any] | None = None,
) -> bytes:
    """``plan.png`` of the same scene, drawn with matplotlib (reproducible byte for byte)."""
    scene = build_scene(artifacts, zoom=zoom, log=log, verdict=verdict)
    require("matplotlib.backends.backend_agg", "drawing a PNG figure")
    with png_style():
        figure = figure_of(scene)
        png = io.BytesIO()
        figure.savefig(
            png, format="png", metadata={"Software": None}, pil_kwargs={"compress_level": 3}
        )
    return png.getvalue()


@contextlib.contextmanager
def png_style() -> Iterator[None]:
    """Matplotlib settings the PNG is drawn with: no path simplification, and text laid out
    at the font's own advance widths (hinting would round each glyph to whole pixels and
    make a name wider than its layout box).

    Every text is drawn as it is written, as the SVG draws it: matplotlib would otherwise read
    the part of a mission's name between two dollar signs as mathtext (a different picture,
    or a parse error).  A character DejaVu Sans lacks is drawn as its placeholder box, which
    the layout measured at the widest glyph, so matplotlib's warning about it is not the
    user's business."""
    import warnings

    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib import rc_context

    with (
        rc_context(
            {"path.simplify": False, "text.hinting": "no_hinting", "text.parse_math": False}
        ),
        warnings.catch_warnings(),
    ):
        warnings.filterwarnings("ignore", "Glyph .* missing from font", UserWarning)
        yield


def figure_of(scene: Scene) -> Any:
    """The matplotlib figure of ``scene``: its :func:`.layout.layout` at 150 dpi.

    The figure measures the layout's width and height in hundredths of an inch, so one figure
    pixel is 1.5 device pixels and text sizes convert at 0.72 points per figure pixel: the
    picture is the SVG's, scaled.  Texts carry a ``gid`` (``title``, ``label``, ``legend``,
    ``extent``, ``bar``) so a test can find them.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patheffects import withStroke
    from matplotlib.transforms import Affine2D

    figure_layout = layout(scene)
    width, height = figure_layout.width, figure_layout.height
    figure = Figure(figsize=(width / 100, height / 100), dpi=150)
    FigureCanvasAgg(figure)
    pixels = Affine2D().scale(1 / 100, -1 / 100).translate(0, height / 100)
    transform = pixels + figure.dpi_scale_trans
    canvas = figure_layout.canvas
    axes = figure.add_axes(
        (
            canvas.left / width,
            1 - (canvas.top + canvas.height) / height,
            canvas.width / width,
            canvas.height / height,
        )
    )
    draw_scene(axes, scene)
    axes.set_xlim(scene.view[0], scene.view[2])
    axes.set_ylim(scene.view[1], scene.view[3])
    axes.set_aspect("auto")  # the layout's scale is already the same along x and y
    axes.set_axis_off()

    def text(x: float, y: float, value: str, size: float, gid: str, **style: Any) -> Any:
        return figure.text(x, y, value, transform=transform, fontsize=size * _PT, gid=gid, **style)

    text(canvas.left, PAD + 12, figure_layout.title, TITLE_PX, "title", va="baseline")
    halo = [withStroke(linewidth=2 * LABEL_HALO * _PT, foreground="white", alpha=0.85)]
    for label in figure_layout.labels:
        text(
            label.x,
            label.y + baseline_offset(label.font_px),
            label.text,
            label.font_px,
            "label",
            ha="center",
            va="baseline",
            path_effects=halo,
            zorder=8,
        )
    for mark in scene.play:
        px, py = canvas.pixel(mark.position)
        text(
            px + 8,
            py + 4,
            shown(mark.text),
            FONT_PX,
            "play-text",
            va="baseline",
            color=PLAY_COLOUR,
            path_effects=[withStroke(linewidth=3 * _PT, foreground="white")],
            zorder=8,
        )
    for number, violation in enumerate(scene.violations, start=1):
        vx, vy = canvas.pixel(violation.position)
        text(
            vx + 8,
            vy - 6,
            str(number),
            FONT_PX,
            "violation-number",
            va="baseline",
            color="#dd0000",
            path_effects=[withStroke(linewidth=3 * _PT, foreground="white")],
            zorder=8,
        )
    text(
        canvas.left,
        figure_layout.extent_y,
        figure_layout.extent_text,
        SMALL_PX,
        "extent",
        va="baseline",
        color="#555555",
    )
    _legend(figure, transform, scene, figure_layout)
    return figure


def _legend(figure: Any, transform: Any, scene: Scene, figure_layout: FigureLayout) -> None:
    """The layout's legend rows and colour bar, in figure pixels."""
    from matplotlib.colors import LinearSegmentedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle

    def line(x: float, y: float, colour: str, width: float, style: Any = "-") -> None:
        figure.add_artist(
            Line2D(
                [x, x + 22],
                [y, y],
                color=colour,
                linewidth=width * _PT,
                linestyle=style,
                transform=transform,
            )
        )

    def box(x: float, y: float, face: str, alpha: float, edge: str, width: float) -> None:
        figure.add_artist(
            Rectangle(
                (x, y - 5),
                22,
                10,
                facecolor=face,
                alpha=alpha,
                edgecolor=edge,
                linewidth=width * _PT,
                transform=transform,
            )
        )

    region_colour = scene.regions[0].colour if scene.regions else "#000000"
    for row in figure_layout.legend:
        cy = row.y - 4
        swatch = True
        match row.kind:
            case "hole":
                box(row.x, cy, "#9a9a9a", 1.0, "black", 1.2)
            case "region":
                box(row.x, cy, region_colour, 0.35, region_colour, 1.0)
            case "task-region":
                box(row.x, cy, "#1f1f1f", 0.8, "#1f1f1f", 1.0)
            case "mesh":
                line(row.x, cy, "#b0b0b0", 0.6)
            case "plan":
                line(row.x, cy, "#1f3b73", 1.0)
            case "cycle":
                line(row.x, cy, "#c0392b", 1.0, "--")
            case "log":
                line(row.x, cy, "#e4007c", 2.0)
            case "start":
                figure.add_artist(
                    Line2D(
                        [row.x + 11],
                        [cy],
                        marker="o",
                        markersize=8 * _PT,
                        markerfacecolor="white",
                        markeredgecolor="black",
                        markeredgewidth=1.6 * _PT,
                        linestyle="none",
                        transform=transform,
                    )
                )
            case "violation":
                figure.add_artist(
                    Line2D(
                        [row.x + 6, row.x + 16, row.x + 11, row.x + 16, row.x + 6],
                        [cy - 5, cy + 5, cy, cy - 5, cy + 5],
                        color="#dd0000",
                        linewidth=2.4 * _PT,
                        transform=transform,
                    )
                )
            case _:
                swatch = False
        figure.text(
            row.x + 30 if swatch else row.x,
            row.y,
            row.text,
            transform=transform,
            fontsize=row.font_px * _PT,
            va="baseline",
            gid="legend",
        )
    bar = figure_layout.colour_bar
    if bar is not None:
        width, height = figure_layout.width, figure_layout.height
        axes = figure.add_axes(
            (
                bar.x0 / width,
                1 - bar.y1 / height,
                (bar.x1 - bar.x0) / width,
                (bar.y1 - bar.y0) / height,
            )
        )
        cmap = LinearSegmentedColormap.from_list("arc", [viridis(i / 10) for i in range(11)])
        axes.imshow([[i / 255 for i in range(256)]], aspect="auto", cmap=cmap, extent=(0, 1, 0, 1))
        axes.set_axis_off()
        for x, value, align in (
            (bar.x0, "0", "left"),
            (bar.x1, figure_layout.colour_bar_end, "right"),
        ):
            figure.text(
                x,
                bar.y1 + 12,
                value,
                transform=transform,
                fontsize=FONT_PX * _PT,
                ha=align,
                va="baseline",
                gid="bar",
            )


def draw_scene(axes: Any, scene: Scene) -> None:
    """Draw ``scene``'s map on matplotlib ``axes`` in world coordinates (line widths and
    marker sizes as the SVG's, in figure pixels converted to points)."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.patches import Polygon as PolygonPatch

    axes.add_patch(PolygonPatch(scene.boundary, closed=True, facecolor="white", zorder=0))
    if scene.components:
        # Pieces of free space may lie inside holes: paint the holes first, then the pieces
        # and their own holes over them, all below the regions and the mesh.
        for layer, (rings, colour) in enumerate(
            (
                (scene.holes, "#9a9a9a"),
                (scene.components, "white"),
                (scene.component_holes, "#9a9a9a"),
            )
        ):
            if rings:
                axes.add_collection(
                    PolyCollection(
                        list(rings),
                        facecolors=colour,
                        edgecolors="black",
                        linewidths=1.2 * _PT,
                        zorder=0.2 + 0.1 * layer,
                    )
                )
    emphasised = [r for r in scene.regions if scene.emphasise_task_regions and r.named_by_task]
    plain = [r for r in scene.regions if r not in emphasised]
    if plain:
        axes.add_collection(
            PolyCollection(
                [r.polygon for r in plain],
                facecolors=[r.colour for r in plain],
                edgecolors=[r.colour for r in plain],
                alpha=0.30,
                linewidths=0.8 * _PT,
                zorder=1,
                gid="regions",
            )
        )
    if emphasised:
        axes.add_collection(
            PolyCollection(
                [r.polygon for r in emphasised],
                facecolors="#1f1f1f",
                edgecolors="#1f1f1f",
                alpha=0.8,
                linewidths=0.8 * _PT,
                zorder=1.5,
                gid="task-regions",
            )
        )
    if len(scene.mesh_edges):
        axes.add_collection(
            LineCollection(
                list(scene.mesh_edges.reshape(-1, 2, 2)),
                colors="#b0b0b0",
                linewidths=0.4 * _PT,
                zorder=2,
                gid="mesh",
            )
        )
    if scene.holes and not scene.components:
        # Line widths are in points: a hole thinner than a pixel still shows as a wall.
        axes.add_collection(
            PolyCollection(
                list(scene.holes),
                facecolors="#9a9a9a",
                edgecolors="black",
                linewidths=1.2 * _PT,
                zorder=3,
                gid="holes",
            )
        )
    axes.add_patch(
        PolygonPatch(
            scene.boundary, closed=True, fill=False, edgecolor="black", linewidth=1.5 * _PT
        )
    )
    if len(scene.plan_prefix) >= 2:
        axes.plot(
            *zip(*scene.plan_prefix, strict=True),
            color="#1f3b73",
            linewidth=1.0 * _PT,
            alpha=0.7,
            zorder=4,
        )
    if len(scene.plan_cycle) >= 2 and not scene.plan_stays:
        axes.plot(
            *zip(*scene.plan_cycle, strict=True),
            color="#c0392b",
            linewidth=1.0 * _PT,
            linestyle=(0, (4, 3)),
            zorder=4,
        )
    if scene.trajectory is not None and len(scene.trajectory.points) >= 2:
        points = scene.trajectory.points
        fractions = scene.trajectory.fractions
        lines = LineCollection(
            list(itertools.pairwise(points)),
            colors=[viridis(0.5 * (a + b)) for a, b in itertools.pairwise(fractions)],
            linewidths=2.0 * _PT,
            zorder=5,
        )
        axes.add_collection(lines)
    if scene.log is not None:
        axes.plot(
            *zip(*scene.log.points, strict=True),
            color="#e4007c",
            linewidth=1.6 * _PT,
            alpha=0.85,
            zorder=5.5,
        )
    if scene.start is not None:
        axes.plot(
            [scene.start[0]],
            [scene.start[1]],
            marker="o",
            markerfacecolor="white",
            markeredgecolor="black",
            markersize=8 * _PT,
            markeredgewidth=1.6 * _PT,
            linestyle="none",
            zorder=5.8,
        )
    if len(scene.play_route) >= 2:
        axes.plot(
            *zip(*scene.play_route, strict=True),
            color=PLAY_COLOUR,
            linewidth=2 * _PT,
            linestyle=(0, (6, 3)),
            zorder=6.5,
            gid="play",
        )
    for mark in scene.play:
        axes.plot(
            [mark.position[0]],
            [mark.position[1]],
            marker="o",
            markerfacecolor=PLAY_COLOUR,
            markeredgecolor="white",
            markersize=10 * _PT,
            linestyle="none",
            zorder=6.6,
            gid="play-step",
        )
    for violation in scene.violations:
        vx, vy = violation.position
        axes.plot(
            [vx],
            [vy],
            marker="x",
            color="#dd0000",
            markersize=12 * _PT,
            markeredgewidth=2.4 * _PT,
            zorder=7,
            gid="violation",
        )
