"""One figure layout, two renderers: names placed without overlap, SVG and PNG agreeing.

The oracles are independent of the layout's own arithmetic: pairwise box tests by brute force,
and matplotlib's real glyph metrics (FreeType on DejaVu Sans) for the width of every drawn
name and the extent of every text in the PNG.
"""

from __future__ import annotations

import itertools
from typing import Any, cast
from xml.etree import ElementTree

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.render.layout import (
    LABEL_HALO,
    LABEL_PX,
    PNG_PIXELS_PER_FIGURE_PIXEL,
    SMALL_PX,
    TITLE_PX,
    Box,
    Canvas,
    layout,
    place_labels,
    text_width,
    wrap,
)
from tlmpc.render.plot import figure_of, png_style
from tlmpc.render.scene import Region, Scene, build_scene
from tlmpc.render.svg import render_svg

matplotlib = pytest.importorskip("matplotlib")
SVG = "{http://www.w3.org/2000/svg}"


def _crowded_mission(columns: int = 6, rows: int = 5) -> dict[str, Any]:
    """A depot-like map: small racks close together, each with two long-named regions."""
    regions: dict[str, list[list[float]]] = {}
    for i, j in itertools.product(range(columns), range(rows)):
        x, y = 2.0 + 3.0 * i, 2.0 + 2.5 * j
        regions[f"keepout_{i}_{j}"] = [[x, y], [x + 1, y], [x + 1, y + 0.8], [x, y + 0.8]]
        regions[f"speed_limit_{i}_{j}"] = [
            [x + 0.2, y + 0.9],
            [x + 0.9, y + 0.9],
            [x + 0.9, y + 1.3],
            [x + 0.2, y + 1.3],
        ]
    return {
        "format": "tlmpc.mission/1",
        "name": "crowded",
        "formula": "F keepout_0_0 & G !speed_limit_3_3",
        "workspace": {"boundary": [[0.0, 0.0], [30.0, 0.0], [30.0, 15.0], [0.0, 15.0]]},
        "regions": regions,
        "robot": {"start": [1.0, 1.0], "max_speed": 1.0},
    }


_VERDICT = {
    "format": "tlmpc.verdict/1",
    "satisfied": False,
    "counterexample": {
        "conjunct": "G !speed_limit_3_3",
        "time": 3.0,
        "position": [11.5, 10.6],
        "message": "entered speed_limit_3_3 at t=3 s (stamp 1432235500.25) at (11.5, 10.6) for "
        "0.5 s while `G !speed_limit_3_3` must hold, "
        "a_very_long_unbroken_word_that_cannot_wrap_on_spaces_at_all_anywhere",
    },
    "workspace_violation": {
        "conjunct": "workspace",
        "time": 4.0,
        "position": [29.9, 14.9],
        "message": "the trajectory left the workspace at t=4 s",
    },
}


def _scene() -> Scene:
    trace = {"format": "tlmpc.trace/1", "points": [[0, 1, 1], [5, 11.5, 10.6], [9, 29.9, 14.9]]}
    return build_scene({"mission.json": _crowded_mission(), "trace.json": trace}, verdict=_VERDICT)


def test_names_do_not_overlap_and_stay_on_the_map() -> None:
    scene = _scene()
    figure = layout(scene)
    canvas = figure.canvas
    area = Box(canvas.left, canvas.top, canvas.left + canvas.width, canvas.top + canvas.height)
    assert len(figure.labels) >= 40  # most of the 60 names find room
    for a, b in itertools.combinations(figure.labels, 2):
        assert not a.box.grown(LABEL_HALO).overlaps(b.box.grown(LABEL_HALO)), (a.name, b.name)
    for label in figure.labels:
        assert label.box.grown(LABEL_HALO).within(area)
    # every name is either drawn or listed as hidden, and the legend says which are hidden
    names = {r.name for r in scene.regions if r.labelled}
    assert {label.name for label in figure.labels} | set(figure.labels_hidden) == names
    if figure.labels_hidden:
        legend = " ".join(row.text for row in figure.legend)
        assert figure.labels_hidden[0] in legend
    # the task's regions are placed first: they always get a name
    assert {"keepout_0_0", "speed_limit_3_3"} <= {label.name for label in figure.labels}


def test_svg_draws_the_layout() -> None:
    scene = _scene()
    figure = layout(scene)
    root = ElementTree.fromstring(render_svg(scene))
    group = next(g for g in root.iter(f"{SVG}g") if g.get("class") == "labels")
    halo, ink = list(group)
    drawn = [(t.text, float(t.get("x", "nan")), float(t.get("y", "nan"))) for t in ink]
    assert [t.text for t in halo] == [t for t, _, _ in drawn]
    assert len(drawn) == len(figure.labels)
    for (name, x, y), label in zip(drawn, figure.labels, strict=True):
        assert name == label.name
        assert x == pytest.approx(label.x, abs=0.051)
        # the baseline sits inside the name's box, below its middle
        assert label.box.y0 < y <= label.box.y1
    assert float(group.get("font-size", "0")) == figure.labels[0].font_px
    assert float(root.get("width", "0")) == pytest.approx(figure.width, abs=0.051)
    assert float(root.get("height", "0")) == pytest.approx(figure.height, abs=0.051)


def _png_texts(scene: Scene) -> tuple[Any, list[tuple[str, str, Box]]]:
    """The PNG figure and its texts' real extents (gid, text, box in figure pixels)."""
    with png_style():
        figure = figure_of(scene)
        renderer = figure.canvas.get_renderer()
        extents = [text.get_window_extent(renderer) for text in figure.texts]
    height_px = figure.get_figheight() * figure.dpi
    found = []
    for text, extent in zip(figure.texts, extents, strict=True):
        if not text.get_text():
            continue
        k = PNG_PIXELS_PER_FIGURE_PIXEL
        found.append(
            (
                str(text.get_gid()),
                text.get_text(),
                Box(
                    extent.x0 / k,
                    (height_px - extent.y1) / k,
                    extent.x1 / k,
                    (height_px - extent.y0) / k,
                ),
            )
        )
    return figure, found


def test_png_draws_the_same_names_where_the_layout_puts_them() -> None:
    scene = _scene()
    figure_layout = layout(scene)
    figure, texts = _png_texts(scene)
    assert figure.get_figwidth() * figure.dpi == pytest.approx(
        figure_layout.width * PNG_PIXELS_PER_FIGURE_PIXEL
    )
    labels = [(text, box) for gid, text, box in texts if gid == "label"]
    assert [text for text, _ in labels] == [label.text for label in figure_layout.labels]
    for (_, real), label in zip(labels, figure_layout.labels, strict=True):
        # real glyph metrics: the ink lies within the layout's box (its width estimate is an
        # upper bound) and is centred where the layout says
        assert real.x1 - real.x0 <= label.box.x1 - label.box.x0 + 0.5
        assert (real.x0 + real.x1) / 2 == pytest.approx(label.x, abs=0.75)
        assert real.y0 >= label.box.y0 - 0.75
        assert real.y1 <= label.box.y1 + 0.75
    for (a_name, a), (b_name, b) in itertools.combinations(labels, 2):
        assert not a.overlaps(b), (a_name, b_name)
    # the legend rows are the layout's, in order
    legend = [text for gid, text, _ in texts if gid == "legend"]
    assert legend == [row.text for row in figure_layout.legend]


def test_nothing_in_the_png_is_cut_at_the_edge() -> None:
    scene = _scene()
    figure_layout = layout(scene)
    _, texts = _png_texts(scene)
    page = Box(0.0, 0.0, figure_layout.width, figure_layout.height)
    assert any(gid == "legend" and "violation 2" in text for gid, text, _ in texts)
    for gid, text, box in texts:
        assert box.within(page.grown(0.5)), (gid, text, box)


def test_svg_and_png_have_the_same_elements() -> None:
    scene = _scene()
    root = ElementTree.fromstring(render_svg(scene))
    figure, texts = _png_texts(scene)
    svg_texts = [t.text for t in root.iter(f"{SVG}text") if t.text]
    group = next(g for g in root.iter(f"{SVG}g") if g.get("class") == "labels")
    names = len(list(group)[1])
    # every text, the SVG drawing the names and violation numbers twice (a halo under each)
    doubled = ("label", "violation-number")
    assert sorted(svg_texts) == sorted(
        [text for _, text, _ in texts] + [text for gid, text, _ in texts if gid in doubled]
    )
    assert names == sum(1 for gid, _, _ in texts if gid == "label")
    (axes, *_) = figure.axes
    crosses = [line for line in axes.get_lines() if line.get_gid() == "violation"]
    svg_crosses = [p for p in root.iter(f"{SVG}path") if p.get("stroke") == "#d00"]
    assert len(crosses) == len(scene.violations) == 2
    assert len(svg_crosses) == len(crosses) + 2  # and a legend swatch for each


@pytest.mark.filterwarnings("ignore:Glyph .* missing from font")
@given(st.text(st.characters(blacklist_categories=("Cc", "Cs")), min_size=1, max_size=30))
@settings(max_examples=40, deadline=None)
def test_the_width_estimate_bounds_the_real_width(name: str) -> None:
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    font = FontProperties(family="DejaVu Sans")
    text = name.replace("$", "s")  # no mathtext
    real, _, _ = TextToPath().get_text_width_height_descent(text, font, ismath=False)
    # the width in points at the font's size: per point, the width in ems (FreeType's
    # advances are in 1/64 of a pixel at 100 pixels per em: 1.6e-4 em of rounding a glyph)
    assert real / font.get_size_in_points() <= text_width(text, 1.0) + 2e-4 * len(text)


_rectangles = st.lists(
    st.tuples(
        st.floats(0, 95),
        st.floats(0, 45),
        st.floats(0.05, 20),
        st.floats(0.05, 10),
        st.text(st.characters(min_codepoint=32, max_codepoint=0x2FFF), min_size=1, max_size=16),
    ),
    min_size=1,
    max_size=40,
)


@given(_rectangles)
@settings(max_examples=60, deadline=None)
def test_placement_never_overlaps(rectangles: list[tuple[float, float, float, float, str]]) -> None:
    canvas = Canvas.of((0.0, 0.0, 100.0, 50.0))
    regions = []
    for index, (x, y, w, h, name) in enumerate(rectangles):
        polygon = ((x, y), (x + w, y), (x + w, y + h), (x, y + h))
        regions.append(
            Region(
                name=f"{name}{index}",
                polygon=polygon,
                colour="#000",
                named_by_task=index % 3 == 0,
                labelled=True,
                label_at=(x + w / 2, y + h / 2),
            )
        )
    marker = Box(10.0, 10.0, 30.0, 30.0)
    placed, hidden = place_labels(regions, canvas, [marker])
    area = Box(canvas.left, canvas.top, canvas.left + canvas.width, canvas.top + canvas.height)
    boxes = [label.box.grown(LABEL_HALO) for label in placed]
    for a, b in itertools.combinations(boxes, 2):
        assert not a.overlaps(b)
    for box in boxes:
        assert box.within(area)
        assert not box.overlaps(marker)
    assert sorted([label.name for label in placed] + list(hidden)) == sorted(
        r.name for r in regions
    )


def _reference_wrap(text: str, font_px: float, width: float, lines: int) -> list[str]:
    """The wrapping :func:`wrap` promises, written the slow and obvious way: every word cut
    into the longest prefixes that fit (at least one character; two when any longer cut is
    tried), greedy lines, the tail past ``lines`` cut and ended with an ellipsis."""

    def fits(piece: str) -> bool:
        return not text_width(piece, font_px) > width

    words: list[str] = []
    for word in text.split():
        while not fits(word) and len(word) > 1:
            fitting = [c for c in range(2, len(word)) if fits(word[:c])]
            cut = max(fitting, default=1)
            words.append(word[:cut])
            word = word[cut:]
        words.append(word)
    out: list[str] = []
    for word in words:
        if out and fits(f"{out[-1]} {word}"):
            out[-1] = f"{out[-1]} {word}"
        else:
            out.append(word)
    if len(out) > lines:
        last = out[lines - 1]
        while last and not fits(last + " …"):
            last = last[:-1]
        out = [*out[: lines - 1], last.rstrip() + " …"]
    return out


@settings(max_examples=300, deadline=None)
@given(
    text=st.text(alphabet="aWil.M –é\u6f22\n", max_size=120),
    font_px=st.sampled_from([SMALL_PX, LABEL_PX, TITLE_PX, 3.7]),
    width=st.sampled_from([0.0, 4.0, 12.0, 40.0, 120.0, 204.0]),
    lines=st.integers(1, 5),
)
def test_wrap_equals_the_reference_wrapping(
    text: str, font_px: float, width: float, lines: int
) -> None:
    assert wrap(text, font_px, width, lines) == _reference_wrap(text, font_px, width, lines)


@pytest.mark.parametrize("text", ["x" * 200_000, "word " * 40_000, "\u6f22" * 200_000])
def test_a_huge_text_wraps_with_few_measurements(
    text: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A 200,000-character title or name is measured a bounded number of times, on short
    texts only (the old cut re-measured every prefix: cubic, hours for this text)."""
    from tlmpc.render import layout

    measured: list[int] = []

    def counting(piece: str, font_px: float) -> float:
        measured.append(len(piece))
        # fail at once rather than measure for hours
        assert len(measured) < 2_000
        assert sum(measured) < 50_000
        return text_width(piece, font_px)

    monkeypatch.setattr(layout, "text_width", counting)
    title = wrap(text, TITLE_PX, 1100.0, lines=1)
    legend = wrap(text, SMALL_PX, 194.0)
    assert len(title) == 1
    assert len(legend) == 4
    assert legend[-1].endswith(" …")


def _hostile_scene() -> Scene:
    """The crowded scene with control, direction, noncharacter and surrogate characters in its
    title, two region names and a violation message."""
    mission = _crowded_mission()
    mission["name"] = "\x01" * 200
    regions = mission["regions"]
    regions["keepout_0_0\x1b[31m\u202e"] = regions.pop("keepout_0_0")
    regions["dock\uffff\ud800"] = regions.pop("keepout_5_4")
    counterexample = dict(cast("dict[str, Any]", _VERDICT["counterexample"]))
    counterexample["message"] = "entered \x07\x08 hazard\u2028at \ufffe\udfff " + "\x0b" * 80
    verdict = {**_VERDICT, "counterexample": counterexample}
    trace = {"format": "tlmpc.trace/1", "points": [[0, 1, 1], [5, 11.5, 10.6], [9, 29.9, 14.9]]}
    return build_scene({"mission.json": mission, "trace.json": trace}, verdict=verdict)


def test_unsafe_characters_are_escaped_before_the_layout_measures() -> None:
    scene = _hostile_scene()
    figure_layout = layout(scene)
    svg = render_svg(scene)
    root = ElementTree.fromstring(svg)  # the XML parser: well-formed, every character allowed
    _, texts = _png_texts(scene)
    # the SVG writes and the PNG draws the same texts: those the layout measured
    svg_texts = [t.text for t in root.iter(f"{SVG}text") if t.text]
    doubled = ("label", "violation-number")
    assert sorted(svg_texts) == sorted(
        [text for _, text, _ in texts] + [text for gid, text, _ in texts if gid in doubled]
    )
    title = next(text for gid, text, _ in texts if gid == "title")
    assert title == figure_layout.title
    assert title.startswith("\\x01\\x01")
    assert title.endswith(" …")
    assert all(ch.isprintable() for text in svg_texts for ch in text)
    # the title, as written, fits the figure (measured by the layout's metric and by FreeType)
    assert text_width(title, TITLE_PX) <= figure_layout.width - 2 * 14.0
    page = Box(0.0, 0.0, figure_layout.width, figure_layout.height)
    for gid, text, box in texts:
        assert box.within(page.grown(0.5)), (gid, text, box)
    drawn = {label.text for label in figure_layout.labels}
    assert "keepout_0_0\\x1b[31m\\u202e" in drawn
