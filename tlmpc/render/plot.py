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

import io
import itertools
from collections.abc import Mapping, Sequence
from typing import Any

from tlmpc.base.extras import require
from tlmpc.render.scene import Scene, build_scene, viridis

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
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib import rc_context
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    x0, y0, x1, y1 = scene.view
    aspect = (y1 - y0) / max(x1 - x0, 1e-12)
    map_width = 6.0
    map_height = min(max(map_width * aspect, 0.6), 7.0)
    if map_width * aspect > 7.0:
        map_width = 7.0 / aspect
    legend_width = 2.6
    figure_width = map_width + legend_width + 0.9
    figure_height = max(map_height + 0.9, 2.8)  # room for the legend beside a wide map
    with rc_context({"path.simplify": False}):
        figure = Figure(figsize=(figure_width, figure_height), dpi=150)
        FigureCanvasAgg(figure)
        axes = figure.add_axes(
            (
                0.6 / figure_width,
                (figure_height - 0.45 - map_height) / figure_height,  # top-aligned
                map_width / figure_width,
                map_height / figure_height,
            )
        )
        handles = draw_scene(axes, scene)
        legend_left = (0.75 + map_width) / figure_width
        figure.legend(
            handles=handles,
            loc="upper left",
            bbox_to_anchor=(legend_left, 1 - 0.35 / figure_height),
            fontsize=7,
            frameon=False,
        )
        if scene.trajectory is not None:
            # Just under the legend (about 0.19 inch per entry at this font size).
            bar_bottom = max(figure_height - 0.35 - 0.19 * len(handles) - 0.6, 0.35)
            _colour_scale(figure, scene, legend_left, figure_width, figure_height, bar_bottom)
        png = io.BytesIO()
        figure.savefig(
            png, format="png", metadata={"Software": None}, pil_kwargs={"compress_level": 3}
        )
    return png.getvalue()


def _colour_scale(
    figure: Any,
    scene: Scene,
    left: float,
    figure_width: float,
    figure_height: float,
    bottom: float,
) -> None:
    """A small horizontal colour bar under the legend: 0 to the path's length."""
    from matplotlib.colors import LinearSegmentedColormap

    assert scene.trajectory is not None
    bar = figure.add_axes(
        (
            left + 0.05 / figure_width,
            bottom / figure_height,
            1.6 / figure_width,
            0.12 / figure_height,
        )
    )
    cmap = LinearSegmentedColormap.from_list("arc", [viridis(i / 10) for i in range(11)])
    bar.imshow([[i / 255 for i in range(256)]], aspect="auto", cmap=cmap, extent=(0, 1, 0, 1))
    bar.set_yticks([])
    bar.set_xticks([0, 1], ["0", f"{scene.trajectory.length:.4g}"], fontsize=7)
    bar.set_title("trajectory: distance travelled", fontsize=7)


def draw_scene(axes: Any, scene: Scene) -> list[Any]:
    """Draw ``scene`` on matplotlib ``axes``; return the legend's handles."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.patches import Polygon as PolygonPatch

    handles: list[Any] = []
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
                        linewidths=0.9,
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
                linewidths=0.6,
                zorder=1,
            )
        )
        handles.append(Patch(facecolor=plain[0].colour, alpha=0.4, label="region"))
    if emphasised:
        axes.add_collection(
            PolyCollection(
                [r.polygon for r in emphasised],
                facecolors="#1f1f1f",
                edgecolors="black",
                alpha=0.8,
                linewidths=0.8,
                zorder=1.5,
            )
        )
        handles.append(Patch(facecolor="#1f1f1f", alpha=0.8, label="task region"))
    if len(scene.mesh_edges):
        axes.add_collection(
            LineCollection(
                list(scene.mesh_edges.reshape(-1, 2, 2)), colors="#b0b0b0", linewidths=0.3, zorder=2
            )
        )
        handles.append(Line2D([], [], color="#b0b0b0", linewidth=0.6, label="triangulation"))
    if scene.holes and not scene.components:
        # Line widths are in points: a hole thinner than a pixel still shows as a wall.
        axes.add_collection(
            PolyCollection(
                list(scene.holes),
                facecolors="#9a9a9a",
                edgecolors="black",
                linewidths=0.9,
                zorder=3,
            )
        )
    if scene.holes or scene.component_holes:
        handles.append(Patch(facecolor="#9a9a9a", edgecolor="black", label="obstacle (hole)"))
    axes.add_patch(
        PolygonPatch(scene.boundary, closed=True, fill=False, edgecolor="black", linewidth=1.2)
    )
    if len(scene.plan_prefix) >= 2:
        axes.plot(
            *zip(*scene.plan_prefix, strict=True),
            color="#1f3b73",
            linewidth=0.8,
            alpha=0.7,
            zorder=4,
        )
        handles.append(Line2D([], [], color="#1f3b73", linewidth=0.8, label="plan (triangles)"))
    if len(scene.plan_cycle) >= 2 and not scene.plan_stays:
        axes.plot(
            *zip(*scene.plan_cycle, strict=True),
            color="#c0392b",
            linewidth=0.8,
            linestyle="--",
            zorder=4,
        )
        handles.append(
            Line2D([], [], color="#c0392b", linewidth=0.8, linestyle="--", label="plan cycle")
        )
    if scene.trajectory is not None and len(scene.trajectory.points) >= 2:
        points = scene.trajectory.points
        fractions = scene.trajectory.fractions
        lines = LineCollection(
            list(itertools.pairwise(points)),
            colors=[viridis(0.5 * (a + b)) for a, b in itertools.pairwise(fractions)],
            linewidths=1.6,
            zorder=5,
        )
        axes.add_collection(lines)
        handles.append(Line2D([], [], color=viridis(0.5), linewidth=1.6, label="trajectory"))
    if scene.log is not None:
        axes.plot(
            *zip(*scene.log.points, strict=True),
            color="#e4007c",
            linewidth=1.2,
            alpha=0.85,
            zorder=5.5,
        )
        handles.append(Line2D([], [], color="#e4007c", linewidth=1.2, label="recorded log"))
    if scene.start is not None:
        axes.plot(
            [scene.start[0]],
            [scene.start[1]],
            marker="o",
            markerfacecolor="white",
            markeredgecolor="black",
            markersize=4,
            linestyle="none",
            zorder=5.8,
        )
        handles.append(
            Line2D(
                [],
                [],
                marker="o",
                markerfacecolor="white",
                markeredgecolor="black",
                markersize=4,
                linestyle="none",
                label="start",
            )
        )
    for number, violation in enumerate(scene.violations, start=1):
        vx, vy = violation.position
        axes.plot([vx], [vy], marker="x", color="#d00", markersize=8, markeredgewidth=2, zorder=7)
        axes.annotate(
            str(number),
            (vx, vy),
            xytext=(5, 5),
            textcoords="offset points",
            color="#d00",
            fontsize=8,
            zorder=7,
        )
        handles.append(
            Line2D(
                [],
                [],
                marker="x",
                color="#d00",
                linestyle="none",
                label=f"violation {number}: {violation.message[:60]}",
            )
        )
    x0, y0, x1, y1 = scene.view
    for region in scene.regions:
        if region.labelled:
            xs = [p[0] for p in region.polygon]
            ys = [p[1] for p in region.polygon]
            # A region narrower than its name gets the name just above it, not over it.
            small = max(xs) - min(xs) < 0.012 * len(region.name) * (x1 - x0)
            axes.text(
                region.label_at[0],
                max(ys) if small else region.label_at[1],
                region.name,
                ha="center",
                va="bottom" if small else "center",
                fontsize=7,
                zorder=6,
                bbox={"boxstyle": "round,pad=0.1", "fc": "white", "alpha": 0.6, "lw": 0},
            )
    axes.set_xlim(x0, x1)
    axes.set_ylim(y0, y1)
    axes.set_aspect("equal")
    axes.tick_params(labelsize=7)
    axes.set_title(scene.title, fontsize=9)
    if scene.regions_omitted:
        handles.append(
            Line2D(
                [], [], linestyle="none", label=f"{scene.regions_omitted:,} other regions not drawn"
            )
        )
    if scene.mesh_omitted:
        handles.append(
            Line2D(
                [],
                [],
                linestyle="none",
                label=f"mesh of {scene.mesh_omitted:,} triangles not drawn",
            )
        )
    return handles
