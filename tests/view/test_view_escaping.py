"""The view shows names and messages as every tlmpc output does (``printable``): control and
direction characters, noncharacters and lone surrogates as visible escapes, checked in a real
Chromium against the Python rule for the first and last code point of every escaped range."""

from __future__ import annotations

import io
import json
import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from chromium import Browser, find_chromium
from ci_oracles import oracle_required

from tlmpc.base.errors import UNSAFE_RANGES, printable
from tlmpc.cli import main
from tlmpc.view import render_html, scene_from_output
from tlmpc.view.html import unsafe_class

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = find_chromium()

#: the first and last code point of every escaped range, each beside safe characters (an
#: emoji's surrogate pair in JavaScript must not be taken for two lone surrogates)
_EDGES = "".join(f"a{chr(first)}😀{chr(last)}é" for first, last in UNSAFE_RANGES)


def test_the_page_escapes_the_ranges_of_the_one_rule() -> None:
    page = render_html({"title": "x"})
    assert "/*UNSAFE*/" not in page
    assert f"new RegExp({json.dumps(unsafe_class())}, " in page
    pattern = re.compile(
        "["
        + "".join(
            f"\\U{first:08x}-\\U{last:08x}"
            for first, last in (
                (int(a, 16), int(b, 16))
                for a, b in re.findall(r"\\u\{(\w+)\}-\\u\{(\w+)\}", unsafe_class())
            )
        )
        + "]"
    )
    for code in list(range(0x3000)) + list(range(0xD700, 0x10100)) + [0x10FFFE, 0x10FFFF]:
        assert bool(pattern.match(chr(code))) == (printable(chr(code), keep="") != chr(code))


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    pytest.importorskip("websocket")
    assert CHROMIUM is not None
    with Browser(CHROMIUM) as running:
        yield running


@pytest.mark.slow
@oracle_required(CHROMIUM is not None, "chromium")
def test_the_view_shows_every_name_escaped_as_printable_does(
    browser: Browser, tmp_path: Path
) -> None:
    out = tmp_path / "out"
    code = main(
        ["compile", str(ROOT / "specs" / "example1.yaml"), "-o", str(out), "-q"],
        out=io.StringIO(),
        err=io.StringIO(),
    )
    assert code == 0
    scene = scene_from_output(out)
    scene["title"] = "\u202ecod.exe.csv against " + _EDGES
    scene["formula"] = "F \u2066dock\u2069"
    label = scene["labels"][0]
    hostile = label["name"] + "\u202e\x1b[31m\ud800"
    scene["regions"][hostile] = scene["regions"].pop(label["name"])
    label["name"] = hostile
    page = tmp_path / "page.html"
    page.write_text(render_html(scene), encoding="utf-8", errors="surrogatepass")
    browser.errors.clear()
    browser.open(page)
    assert browser.errors == []
    shown = browser.evaluate(
        "[document.getElementById('title').textContent,"
        " document.getElementById('formula').textContent,"
        " [...document.querySelectorAll('text.label')].map((n) => n.textContent)]"
    )
    assert shown[0] == printable(scene["title"], keep="")
    assert shown[1] == "F \\u2066dock\\u2069"
    assert printable(hostile, keep="") in shown[2]
