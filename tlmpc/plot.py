"""Figures of a compiled mission, drawn from its artifacts alone (headless, reproducible).

``render_plan`` draws the workspace, holes, regions with their names, the triangulation, the
discrete plan (prefix solid, cycle dashed) and the simulated trajectory coloured by time, and
returns PNG and SVG bytes.  The same artifacts always give the same bytes: no timestamps, a
fixed SVG hash salt, no software tag.
"""

from __future__ import annotations

import io
import itertools
from collections.abc import Mapping, Sequence
from typing import Any

# Colours for regions, cycled; chosen to stay readable on top of each other when translucent.
_REGION_COLOURS = (
    "#4e79a7",
    "#f28e2b",
    "#59a14f",
    "#e15759",
    "#76b7b2",
    "#edc948",
    "#b07aa1",
    "#ff9da7",
    "#9c755f",
)
_MAX_REGION_NAMES = 60  # beyond this many regions the names only clutter the picture
_MAX_MESH_TRIANGLES = 20_000  # a denser mesh is a grey blur at any printable size
_MAX_VECTOR_SEGMENTS = 500  # longer trajectories go into the SVG as an embedded image


def _polygon_xy(points: Sequence[Sequence[float]]) -> tuple[list[float], list[float]]:
    xs = [float(p[0]) for p in points]
    ys = [float(p[1]) for p in points]
    return [*xs, xs[0]], [*ys, ys[0]]


def _centroids(abstraction: Mapping[str, Any], triangles: Sequence[int]) -> list[list[float]]:
    vertices = abstraction["vertices"]
    tris = abstraction["triangles"]
    result = []
    for t in triangles:
        corners = [vertices[i] for i in tris[t]]
        result.append([sum(c[0] for c in corners) / 3.0, sum(c[1] for c in corners) / 3.0])
    return result


def draw_plan(axes: Any, artifacts: Mapping[str, Any]) -> None:
    """Draw everything the artifacts in ``artifacts`` (file name -> document) describe."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.patches import Polygon as PolygonPatch

    mission = artifacts["mission.json"]
    workspace = mission["workspace"]
    boundary = workspace["boundary"]
    axes.add_patch(
        PolygonPatch(
            boundary, closed=True, facecolor="white", edgecolor="black", linewidth=1.2, zorder=0
        )
    )
    for hole in workspace.get("holes", []):
        axes.add_patch(
            PolygonPatch(
                hole,
                closed=True,
                facecolor="#9a9a9a",
                edgecolor="black",
                hatch="//",
                linewidth=0.8,
                zorder=3,
            )
        )
    regions: Mapping[str, Any] = mission["regions"]
    ordered = sorted(regions.items())
    colours = [_REGION_COLOURS[i % len(_REGION_COLOURS)] for i in range(len(ordered))]
    axes.add_collection(
        PolyCollection(
            [polygon for _, polygon in ordered],
            facecolors=colours,
            edgecolors=colours,
            alpha=0.30,
            linewidths=0.8,
            zorder=1,
            rasterized=len(ordered) > _MAX_REGION_NAMES,
        )
    )
    # The regions the task names are emphasised and always labelled (Example 8's black rooms).
    from tlmpc.ltl.parser import parse_ltl

    named = parse_ltl(mission["formula"]).props() if mission.get("formula") else frozenset()
    emphasised = [(n, p) for n, p in ordered if n in named]
    if emphasised and len(regions) > _MAX_REGION_NAMES:
        axes.add_collection(
            PolyCollection(
                [p for _, p in emphasised],
                facecolors="#1f1f1f",
                edgecolors="black",
                alpha=0.8,
                linewidths=0.8,
                zorder=1.5,
            )
        )
    for name, polygon in ordered:
        if len(regions) <= _MAX_REGION_NAMES or name in named:
            xs, ys = _polygon_xy(polygon)
            axes.text(
                sum(xs[:-1]) / (len(xs) - 1),
                sum(ys[:-1]) / (len(ys) - 1),
                name,
                ha="center",
                va="center",
                fontsize=8,
                zorder=6,
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "alpha": 0.7, "lw": 0},
            )

    abstraction = artifacts.get("abstraction.json")
    if abstraction is not None and len(abstraction["triangles"]) <= _MAX_MESH_TRIANGLES:
        vertices = abstraction["vertices"]
        xs = [v[0] for v in vertices]
        ys = [v[1] for v in vertices]
        axes.triplot(
            xs,
            ys,
            abstraction["triangles"],
            color="#b0b0b0",
            linewidth=0.3,
            zorder=2,
            rasterized=len(abstraction["triangles"]) > 2_000,
        )

    witness = artifacts.get("witness.json")
    if witness is not None and abstraction is not None:
        prefix = list(witness["prefix"])
        cycle = list(witness["cycle"])
        path = _centroids(abstraction, [*prefix, *cycle[:1]]) if prefix else []
        if len(path) >= 2:
            axes.plot(
                [p[0] for p in path],
                [p[1] for p in path],
                color="#1f3b73",
                linewidth=1.0,
                marker=".",
                markersize=3,
                zorder=4,
                label="plan prefix",
            )
        loop = _centroids(abstraction, [*cycle, cycle[0]])
        axes.plot(
            [p[0] for p in loop],
            [p[1] for p in loop],
            color="#c0392b",
            linewidth=1.0,
            linestyle="--",
            marker=".",
            markersize=3,
            zorder=4,
            label="plan cycle" if len(cycle) > 1 else "stay",
        )

    trace = artifacts.get("trace.json")
    if trace is not None:
        points = trace["points"]
        segments = [[(a[1], a[2]), (b[1], b[2])] for a, b in itertools.pairwise(points)]
        times = [0.5 * (a[0] + b[0]) for a, b in itertools.pairwise(points)]
        if segments:
            lines = LineCollection(
                segments,
                cmap="viridis",
                linewidth=1.8,
                zorder=5,
                rasterized=len(segments) > _MAX_VECTOR_SEGMENTS,
            )
            lines.set_array(times)
            axes.add_collection(lines)
            axes.figure.colorbar(lines, ax=axes, fraction=0.046, pad=0.04, label="time [s]")

    start = mission["robot"]["start"]
    axes.plot(
        [start[0]],
        [start[1]],
        marker="o",
        color="black",
        markersize=6,
        zorder=7,
        linestyle="none",
        label="start",
    )
    bx, by = _polygon_xy(boundary)
    margin = 0.02 * max(max(bx) - min(bx), max(by) - min(by))
    axes.set_xlim(min(bx) - margin, max(bx) + margin)
    axes.set_ylim(min(by) - margin, max(by) + margin)
    axes.set_aspect("equal")
    axes.set_xlabel("x")
    axes.set_ylabel("y")
    # A literal title: a `$` in a mission name must not start matplotlib's mathtext.
    axes.set_title(str(mission.get("name") or "tlmpc plan").replace("$", r"\$"), fontsize=10)
    axes.legend(loc="upper right", fontsize=7, framealpha=0.8)


def render_plan(artifacts: Mapping[str, Any]) -> tuple[bytes, bytes]:
    """PNG and SVG bytes of :func:`draw_plan` (reproducible byte for byte)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib import rc_context
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    with rc_context({"svg.hashsalt": "tlmpc", "svg.fonttype": "path", "path.simplify": False}):
        figure = Figure(figsize=(7.0, 6.0), dpi=150)
        FigureCanvasAgg(figure)
        axes = figure.add_subplot(1, 1, 1)
        draw_plan(axes, artifacts)
        # Fixed margins: a layout engine would draw the figure once more just to measure it.
        figure.subplots_adjust(left=0.08, right=0.9, bottom=0.08, top=0.94)
        png = io.BytesIO()
        # zlib level 3: a tenth larger than the default 6, in two thirds of the time.
        figure.savefig(
            png, format="png", metadata={"Software": None}, pil_kwargs={"compress_level": 3}
        )
        svg = io.BytesIO()
        figure.savefig(svg, format="svg", metadata={"Date": None, "Creator": None})
    return png.getvalue(), svg.getvalue()
