"""The view's page and scene without a browser: escaping, self-containment, scene contents."""

from __future__ import annotations

import io
import json
import re
from pathlib import Path

from tlmpc.cli import main
from tlmpc.view import render_html, scene_from_log

ROOT = Path(__file__).resolve().parents[2]


def _embedded(page: str) -> dict[str, object]:
    match = re.search(r'<script id="scene" type="application/json">(.*?)</script>', page, re.S)
    assert match is not None
    data: dict[str, object] = json.loads(match.group(1))
    return data


def test_text_in_the_scene_cannot_close_the_script() -> None:
    scene = {"title": "</script><script>alert(1)</script> <!--<script> & <b>", "trajectory": []}
    page = render_html(scene)
    assert page.count("</script>") == 2  # the template's own two script elements
    assert _embedded(page) == scene
    start = page.index('<script id="scene" type="application/json">') + 43
    data = page[start : page.index("</script>", start)]
    assert not set("<>&") & set(data)  # nothing the HTML parser could take for markup


def test_the_page_needs_no_network() -> None:
    page = render_html({"title": "x"})
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", page)
    assert "default-src 'none'" in page  # and the browser is told to refuse any fetch


def test_scene_of_a_log_marks_segments_through_holes(tmp_path: Path) -> None:
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nworkspace:\n  boundary: {rect: [0, 0, 10, 10]}\n"
        "  holes: [{rect: [4, 4, 6, 6]}]\nregions:\n  goal: {rect: [8, 8, 9, 9]}\n"
        "robot: {start: [1, 1]}\ntask:\n  - visit goal\n"
    )
    log = tmp_path / "run.csv"
    # segment 1 (3,3)->(3,7) passes beside the hole; segment 2 (3,7)->(7,3) cuts through it;
    # segment 4 leaves the workspace
    log.write_text("t,x,y\n0,1,1\n1,3,3\n2,3,7\n3,7,3\n4,9.5,9.5\n5,11,9.5\n6,9,9\n")
    scene = scene_from_log(log, mission)
    assert scene["outside"] == [[2, 2], [4, 5]]
    verdict = scene["verdict"]
    assert verdict["satisfied"] is False  # the verifier rejects leaving the workspace too
    assert verdict["workspace_violation"] is not None
    assert len(scene["trajectory"]) == 7


def test_view_usage(tmp_path: Path) -> None:
    err = io.StringIO()
    assert main(["view"], out=io.StringIO(), err=err) == 2
    assert "give either OUT" in err.getvalue()
    assert main(["view", str(tmp_path)], out=io.StringIO(), err=io.StringIO()) == 2
    assert main(["view", "--log", "x.csv"], out=io.StringIO(), err=io.StringIO()) == 2
