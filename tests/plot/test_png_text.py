"""plan.png draws every text as it is written, as plan.svg does.

A mission's name is free text: dollar signs in it are not matplotlib mathtext (which would draw
``$x^2$`` as x² or fail on ``$\\frac{1}{$``), and a character DejaVu Sans lacks is drawn as
its placeholder without a warning on the user's terminal.  The oracle for the drawn width is
FreeType's own measure of the literal text (matplotlib's TextToPath with ``ismath=False``),
compared with the extent of the title's ink in the PNG.
"""

from __future__ import annotations

import io
import warnings
from typing import Any

import pytest

from tlmpc.render.layout import PAD, PNG_PIXELS_PER_FIGURE_PIXEL, TITLE_PX
from tlmpc.render.plot import render_png

pytest.importorskip("matplotlib")
Image = pytest.importorskip("PIL.Image")


def _artifacts(name: str) -> dict[str, Any]:
    return {
        "mission.json": {
            "format": "tlmpc.mission/1",
            "name": name,
            "formula": "F dock",
            "workspace": {"boundary": [[0.0, 0.0], [10.0, 0.0], [10.0, 6.0], [0.0, 6.0]]},
            "regions": {"dock": [[7.0, 1.0], [9.0, 1.0], [9.0, 3.0], [7.0, 3.0]]},
            "robot": {"start": [1.0, 1.0], "max_speed": 1.0},
        }
    }


def _title_ink_width(png: bytes) -> int:
    """The width in PNG pixels of the dark pixels in the title's band (above the map)."""
    image = Image.open(io.BytesIO(png)).convert("L")
    band = image.crop((0, 0, image.width, int((PAD + 16) * PNG_PIXELS_PER_FIGURE_PIXEL)))
    columns = [
        x for x in range(band.width) if min(band.getpixel((x, y)) for y in range(band.height)) < 128
    ]
    return columns[-1] - columns[0] + 1


def _literal_width(text: str) -> float:
    """FreeType's advance width of ``text`` at the title's size, in PNG pixels."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    font = FontProperties(family="DejaVu Sans", size=TITLE_PX)
    width, _, _ = TextToPath().get_text_width_height_descent(text, font, ismath=False)
    return width * PNG_PIXELS_PER_FIGURE_PIXEL


@pytest.mark.parametrize("name", ["route $x^2$ east", "cost $5 and $6", r"a \$ sign $\alpha$"])
def test_dollar_signs_are_drawn_as_written(name: str) -> None:
    ink = _title_ink_width(render_png(_artifacts(name)))
    # the ink lies within the advance width, short of it by the side bearings only; mathtext
    # would drop the dollar signs (and the caret, the backslash): several glyphs narrower
    assert _literal_width(name) - 12 <= ink <= _literal_width(name) + 2


@pytest.mark.parametrize("name", [r"cost $\frac{1}{$", "$^^$", r"$\undefinedcommand$"])
def test_text_that_is_no_valid_mathtext_is_drawn(name: str) -> None:
    png = render_png(_artifacts(name))
    assert _title_ink_width(png) >= _literal_width(name) - 12


def test_a_glyph_the_font_lacks_warns_nobody() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        png = render_png(_artifacts("倉庫 \ufdfa map"))
    assert png.startswith(b"\x89PNG")
    assert [str(w.message) for w in caught] == []
