"""The HTML view in a real headless Chromium: loads offline, draws the scene, animates.

Checks what is drawn (region shapes, the trajectory path, the robot moving as time advances,
the counterexample of a failed verification, the mesh on demand, hover), that the console has
no errors and that the page asks the network for nothing.
"""

from __future__ import annotations

import io
import json
from collections.abc import Iterator
from pathlib import Path

import pytest
from chromium import Browser, find_chromium
from ci_oracles import oracle_required

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = find_chromium()

# Chromium comes from the OS packages (.ci/run installs it): skipped without it on a developer's
# machine, a failure in CI.
pytestmark = oracle_required(CHROMIUM is not None, "chromium")


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    pytest.importorskip("websocket")
    assert CHROMIUM is not None
    with Browser(CHROMIUM) as running:
        yield running


def _run(*argv: str) -> int:
    return main(list(argv), out=io.StringIO(), err=io.StringIO())


def _wait(browser: Browser, expression: str) -> None:
    """Until ``expression`` is true, checked in the page on every animation frame (the
    animation runs on the browser's own clock); no time limit of ours."""
    browser.evaluate(
        "new Promise(resolve => { const check = () => "
        f"({expression}) ? resolve(true) : requestAnimationFrame(check); check(); }})"
    )


def _load(browser: Browser, page: Path) -> None:
    browser.errors.clear()
    browser.requests.clear()
    browser.open(page)
    assert browser.errors == []
    assert all(url.startswith(("file:", "data:", "about:")) for url in browser.requests), (
        browser.requests
    )


@pytest.mark.slow
def test_example8_view(browser: Browser, tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert _run("compile", str(ROOT / "specs" / "example8.yaml"), "-o", str(out), "-q") == 0
    assert _run("view", str(out)) == 0
    page = out / "view.html"
    _load(browser, page)
    mission = json.loads((out / "mission.json").read_text())
    trace = json.loads((out / "trace.json").read_text())
    abstraction = json.loads((out / "abstraction.json").read_text())
    assert browser.evaluate("document.querySelectorAll('#regions path.region').length") == len(
        mission["regions"]
    )
    # the whole trajectory is one path through every sample
    d = browser.evaluate("document.querySelector('path.trajectory').getAttribute('d')")
    assert d.count("L") + 1 == len(trace["points"])
    assert browser.evaluate("document.querySelectorAll('#mesh path').length") == 0  # on demand
    browser.evaluate("document.getElementById('mesh-toggle').click()")
    assert browser.evaluate("document.querySelectorAll('#mesh path.mesh').length") == len(
        abstraction["triangles"]
    )
    duration = trace["points"][-1][0] - trace["points"][0][0]
    assert browser.evaluate("tlmpcView.duration") == pytest.approx(duration)
    start = browser.evaluate("[+robot.getAttribute('cx'), +robot.getAttribute('cy')]")
    assert start == pytest.approx([trace["points"][0][1], -trace["points"][0][2]])
    browser.evaluate("document.getElementById('play').click()")
    _wait(browser, "tlmpcView.time() > 0")
    _wait(browser, "document.getElementById('time').textContent !== '0.00'")
    browser.evaluate("document.getElementById('play').click()")  # pause
    paused = browser.evaluate("tlmpcView.time()")
    assert browser.evaluate("tlmpcView.playing()") is False
    assert browser.evaluate("tlmpcView.time()") == paused
    moved = browser.evaluate("[+robot.getAttribute('cx'), +robot.getAttribute('cy')]")
    assert moved != start
    # between two samples the robot is on the segment joining them, in proportion to time
    (t1, x1, y1), (t2, x2, y2) = trace["points"][10], trace["points"][11]
    browser.evaluate(f"tlmpcView.seek({(t1 + t2) / 2 - trace['points'][0][0]})")
    middle = browser.evaluate("[+robot.getAttribute('cx'), +robot.getAttribute('cy')]")
    assert middle == pytest.approx([(x1 + x2) / 2, -(y1 + y2) / 2])
    # scrubbing to the end puts the robot on the last sample
    browser.evaluate(
        "(() => { const s = document.getElementById('scrub'); s.value = 1000;"
        " s.dispatchEvent(new Event('input')); })()"
    )
    end = browser.evaluate("[+robot.getAttribute('cx'), +robot.getAttribute('cy')]")
    assert end == pytest.approx([trace["points"][-1][1], -trace["points"][-1][2]])
    # hover names the region and the triangle under a point: the centroid of triangle 0
    vertices = abstraction["vertices"]
    corners = [vertices[i] for i in abstraction["triangles"][0]]
    cx = sum(p[0] for p in corners) / 3
    cy = sum(p[1] for p in corners) / 3
    hit = browser.evaluate(f"tlmpcView.describe({cx}, {cy})")
    assert hit["triangle"] == 0
    assert sorted(hit["regions"]) == sorted(abstraction["labels"][0])
    assert browser.errors == []


@pytest.mark.slow
def test_failed_log_verification_view(browser: Browser, tmp_path: Path) -> None:
    # reach-avoid's task forbids the hazard; this log crosses it at x = 8 on its way to the dock,
    # and its way home cuts through the pillar (a hole) at x = 7
    log = tmp_path / "run.csv"
    log.write_text("t,x,y\n0,1,1\n10,4,2\n20,8.5,2\n30,10.8,6.8\n40,1.2,1.2\n")
    mission = ROOT / "specs" / "reach-avoid.yaml"
    assert _run("verify", str(log), "--mission", str(mission)) == 1
    assert _run("view", "--log", str(log), "--mission", str(mission)) == 0
    _load(browser, tmp_path / "run.html")
    assert browser.evaluate("document.querySelectorAll('#regions path.region').length") == 3
    status = browser.evaluate("document.querySelector('#verdict span').textContent")
    assert status == "VIOLATED"
    marker = browser.evaluate(
        "[...document.querySelectorAll('circle.counterexample')]"
        ".map((c) => [+c.getAttribute('cx'), +c.getAttribute('cy')])"
    )
    # every violation: the hole on the way home, and both entries into the hazard
    assert sorted(marker) == [
        pytest.approx([7.0, -4.5833333]),
        pytest.approx([8.0, -2.0]),
        pytest.approx([8.5714286, -5.5]),
    ]
    assert browser.evaluate("document.querySelectorAll('#scrub-wrap .tick').length") == 3
    assert browser.evaluate("document.querySelectorAll('path.violation').length") == 1
    assert "hazard" in browser.evaluate("document.getElementById('verdict').textContent")
    d = browser.evaluate("document.querySelector('path.trajectory').getAttribute('d')")
    assert d.count("L") + 1 == 5
    # "go to the violation" moves time to the moment the hazard is entered (t = 18.89 s)
    browser.evaluate("document.getElementById('jump').click()")
    assert browser.evaluate("tlmpcView.time()") == pytest.approx(18.89, abs=0.01)
    browser.evaluate("document.getElementById('play').click()")
    _wait(browser, "tlmpcView.time() > 18.9")
    assert browser.errors == []


@pytest.mark.slow
def test_an_unlocated_violation_is_stated(browser: Browser, tmp_path: Path) -> None:
    # Example 1's task: p2, p3, p4, then p1; this log never reaches p4 (no place to point at)
    log = tmp_path / "run.csv"
    log.write_text("t,x,y\n0,1.5,1.5\n5,2.5,7.5\n10,8,8\n15,1.5,1.5\n")
    mission = ROOT / "specs" / "example1.yaml"
    assert _run("view", "--log", str(log), "--mission", str(mission)) == 0
    _load(browser, tmp_path / "run.html")
    assert browser.evaluate("document.querySelectorAll('#regions path.region').length") == 4
    # the log simply ends: the verdict is open, and the task's one conjunct is still pending
    text = browser.evaluate("document.getElementById('verdict').textContent")
    assert text.startswith("inconclusive")
    assert "pending" in text
    assert browser.evaluate("document.getElementById('jump').hidden") is True
    assert browser.errors == []


@pytest.mark.slow
def test_a_log_through_a_hole_is_drawn_as_a_violation(browser: Browser, tmp_path: Path) -> None:
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nworkspace:\n  boundary: {rect: [0, 0, 10, 10]}\n"
        "  holes: [{rect: [4, 4, 6, 6]}]\nregions:\n  goal: {rect: [8, 8, 9, 9]}\n"
        "robot: {start: [1, 1]}\ntask:\n  - visit goal\n"
    )
    log = tmp_path / "run.csv"
    log.write_text("t,x,y\n0,1,1\n1,3,3\n2,5,5\n3,7,7\n4,8.5,8.5\n")
    assert _run("view", "--log", str(log), "--mission", str(mission)) == 0
    _load(browser, tmp_path / "run.html")
    assert browser.evaluate("document.querySelectorAll('path.violation').length") == 1
    assert browser.errors == []
