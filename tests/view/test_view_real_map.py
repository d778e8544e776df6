"""What a person sees in the view of a real map (nav2's depot) in headless Chromium.

Measured on the screen, not in the scene: every region name is drawn at the page's label size
in screen pixels at any zoom, no two names overlap, the names cover only a small part of the
map and none leaves it.
"""

from __future__ import annotations

import io
import itertools
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from chromium import Browser, find_chromium
from robot_data import require_shared

from tlmpc.cli import main

CHROMIUM = find_chromium()

pytestmark = [
    pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed"),
    pytest.mark.slow,
]

#: The page's name size (screen pixels) and the line box Chromium gives it.
LABEL_PX = 12


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    pytest.importorskip("websocket")
    assert CHROMIUM is not None
    with Browser(CHROMIUM) as running:
        yield running


@pytest.fixture(scope="module")
def depot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The depot map with its keepout and speed masks, compiled with a body."""
    maps = require_shared("maps")
    work = tmp_path_factory.mktemp("depot")
    mission = work / "depot.yaml"
    quiet = {"out": io.StringIO(), "err": io.StringIO()}
    assert (
        main(
            [
                "import-map",
                str(maps / "depot.yaml"),
                "--keepout",
                str(maps / "depot_keepout.yaml"),
                "--speed",
                str(maps / "depot_speed.yaml"),
                "--radius",
                "0.2",
                "--task",
                "avoid keepout",
                "--task",
                "visit speed_50_1",
                "-o",
                str(mission),
            ],
            **quiet,
        )
        == 0
    )
    out = work / "out"
    assert main(["compile", str(mission), "-o", str(out), "-q"], **quiet) == 0
    assert main(["view", str(out)], **quiet) == 0
    return out / "view.html"


def _labels(browser: Browser) -> list[dict[str, Any]]:
    """The visible names' screen rectangles and their computed font size."""
    value = browser.evaluate(
        "[...document.querySelectorAll('#labels text')]"
        ".filter((t) => t.style.display !== 'none')"
        ".map((t) => { const r = t.getBoundingClientRect();"
        " const m = t.getScreenCTM();"
        " return {name: t.textContent, x0: r.left, y0: r.top, x1: r.right, y1: r.bottom,"
        " size: parseFloat(getComputedStyle(t).fontSize) * m.a}; })"
    )
    assert isinstance(value, list)
    return value


def _map_rect(browser: Browser) -> dict[str, float]:
    value = browser.evaluate(
        "(() => { const r = document.getElementById('map').getBoundingClientRect();"
        " return {x0: r.left, y0: r.top, x1: r.right, y1: r.bottom}; })()"
    )
    assert isinstance(value, dict)
    return value


def _check_what_is_seen(browser: Browser) -> list[dict[str, Any]]:
    labels = _labels(browser)
    assert labels, "no name is drawn"
    area = _map_rect(browser)
    for label in labels:
        # the font is LABEL_PX screen pixels, whatever the map's size in metres
        assert label["size"] == pytest.approx(LABEL_PX, rel=0.02), label
        assert 0.9 * LABEL_PX <= label["y1"] - label["y0"] <= 1.6 * LABEL_PX, label
        for low, high in (("x0", "x1"), ("y0", "y1")):
            assert label[low] >= area[low] - 0.5, label
            assert label[high] <= area[high] + 0.5, label
    # no two names overlap on the screen (the text's own box, as the browser lays it out)
    for a, b in itertools.combinations(labels, 2):
        overlap_x = min(a["x1"], b["x1"]) - max(a["x0"], b["x0"])
        overlap_y = min(a["y1"], b["y1"]) - max(a["y0"], b["y0"])
        assert overlap_x <= 0.5 or overlap_y <= 0.5, (a["name"], b["name"])
    # the names cover a small part of the map
    covered = sum((r["x1"] - r["x0"]) * (r["y1"] - r["y0"]) for r in labels)
    whole = (area["x1"] - area["x0"]) * (area["y1"] - area["y0"])
    assert covered < 0.08 * whole
    return labels


def test_names_on_a_real_map_are_readable_and_do_not_cover_it(
    browser: Browser, depot: Path
) -> None:
    browser.errors.clear()
    browser.open(depot)
    assert browser.errors == []
    before = _check_what_is_seen(browser)
    hidden_before = browser.evaluate("document.getElementById('labels-hidden').textContent")
    # zoom in three steps on the racks (the crowded part): names keep their screen size and
    # more of them find room
    for _ in range(3):
        browser.evaluate(
            "(() => { const r = document.getElementById('map').getBoundingClientRect();"
            " document.getElementById('map').dispatchEvent(new WheelEvent('wheel',"
            " {deltaY: -100, clientX: r.left + 0.62 * r.width, clientY: r.top + 0.6 * r.height,"
            " bubbles: true, cancelable: true})); })()"
        )
    after = _check_what_is_seen(browser)
    names = {label["name"] for label in after}
    assert len(names) >= 1
    if hidden_before:
        # on a closer view the names that were hidden for lack of room come back
        shown_before = {label["name"] for label in before}
        assert names - shown_before
    # back home: the same picture as at first
    browser.evaluate("document.getElementById('map').dispatchEvent(new MouseEvent('dblclick'))")
    assert [label["name"] for label in _labels(browser)] == [label["name"] for label in before]
    assert browser.errors == []


def test_the_real_jackal_log_plays_in_times_from_its_start(
    browser: Browser, tmp_path: Path
) -> None:
    # The Jackal's odometry (ROS 1 bag, 61.18 s stamped from 47.584 s on the robot's clock),
    # against a mission drawn in its odom frame: the slider and every time on the page count
    # from the log's start.
    bag = require_shared("bags/jackal_odometry.bag")
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nworkspace:\n  boundary: {rect: [-12, -5, 6, 25]}\nregions:\n"
        "  goal: {rect: [-10, 20, -8, 23]}\n  pond: {rect: [-2, 8, 1, 12]}\n"
        "robot: {start: [0, 0], max_speed: 2.5}\ntask: [visit goal, avoid pond]\n"
    )
    page = tmp_path / "jackal.html"
    quiet = {"out": io.StringIO(), "err": io.StringIO()}
    assert (
        main(["view", "--log", str(bag), "--mission", str(mission), "-o", str(page)], **quiet) == 0
    )
    browser.errors.clear()
    browser.open(page)
    assert browser.errors == []
    assert browser.evaluate("document.getElementById('duration').textContent") == "61.18"
    assert browser.evaluate("document.getElementById('time').textContent") == "0.00"
    browser.evaluate(
        "(() => { const s = document.getElementById('scrub'); s.value = 500;"
        " s.dispatchEvent(new Event('input')); })()"
    )
    assert browser.evaluate("document.getElementById('time').textContent") == "30.59"
    text = browser.evaluate("document.getElementById('verdict').textContent")
    assert "done at t=56.54 s (stamp 104.125)" in text
    assert "t=1e+02" not in text
    assert "t=104" not in text
    # the names are readable on this map too
    _check_what_is_seen(browser)
