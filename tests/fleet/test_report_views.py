"""The fleet report's views: each log drawn as the batch read it (its reading flags), and a
report whose links always lead to pages of their own logs, also after a run cut short.

The oracles are the logs' geometry: a straight run along y = 5 through the mission's lake
(x from 8 to 12) is violated exactly when it reaches x = 8; and each log's first sample names
it (x0 = 1 + k / 100 for the log of robot k)."""

from __future__ import annotations

import io
import json
import re
from pathlib import Path
from typing import Any

import pytest

import tlmpc.view as view_module
from tlmpc.cli import main

MISSION = """\
version: 1
name: lake
workspace:
  boundary: {rect: [0, 0, 20, 10]}
regions:
  lake: {rect: [8, 3, 12, 7]}
  goal: {rect: [16, 6, 19, 9]}
robot: {start: [1, 1], max_speed: 2.0}
task:
  - avoid lake
  - visit goal
"""


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def _page_verdict(page: Path) -> str:
    found = re.search(r'"verdict":\{"format":"tlmpc.verdict/1","verdict":"(\w+)"', page.read_text())
    assert found is not None
    return found.group(1)


def _links(report: Path) -> dict[str, Path]:
    rows = re.findall(r'<td class="formula">([^<]*)</td>.*?href="([^"]*)"', report.read_text())
    return {log: report.parent / link for log, link in rows}


@pytest.mark.parametrize(
    ("header", "flags", "verdict"),
    [
        # x from 1 to 7, moved 3 to the right: from 4 to 10, into the lake
        ("t,x,y", ["--transform", "3,0,0"], "violated"),
        ("time,px,py", ["--columns", "time,px,py"], "inconclusive"),
        # staying at x = 7 forever, it never visits the goal
        ("t,x,y", ["--assume-stay"], "violated"),
    ],
)
def test_a_view_reads_the_log_as_the_batch_did(
    tmp_path: Path, header: str, flags: list[str], verdict: str
) -> None:
    (tmp_path / "m.yaml").write_text(MISSION)
    log = tmp_path / "logs" / "run.csv"
    log.parent.mkdir()
    log.write_text(f"{header}\n0,1,5\n1,3,5\n2,5,5\n3,7,5\n")
    report = tmp_path / "fleet.html"
    results = tmp_path / "r.jsonl"
    code, _, err = run_cli(
        "verify", str(log.parent), "--mission", str(tmp_path / "m.yaml"), "--no-cache",
        "--report", str(report), "--results", str(results), *flags,
    )  # fmt: skip
    assert code == {"violated": 1, "inconclusive": 4}[verdict], err
    assert json.loads(results.read_text())["verdict"] == verdict
    links = _links(report)
    assert set(links) == {str(log)}
    assert _page_verdict(links[str(log)]) == verdict


def _fleet(folder: Path, crossing: int) -> None:
    """Robots r00 ... r05, each log named run.csv; those of parity ``crossing`` cross the
    lake.  Robot k starts at x0 = 1 + k / 100."""
    for k in range(6):
        log = folder / f"r{k:02d}" / "run.csv"
        log.parent.mkdir(parents=True, exist_ok=True)
        y = 5 if k % 2 == crossing else 1
        log.write_text("t,x,y\n" + "".join(f"{i},{1 + k / 100 + i},{y}\n" for i in range(10)))


def _first_x(page: Path) -> float:
    found = re.search(r'"trajectory":\[\[[^,\]]*,([^,\]]*),', page.read_text())
    assert found is not None
    return float(found.group(1))


def test_a_run_cut_short_leaves_the_earlier_report_and_its_pages(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "m.yaml").write_text(MISSION)
    logs = tmp_path / "logs"
    report = tmp_path / "fleet.html"
    argv = ["verify", str(logs), "--mission", str(tmp_path / "m.yaml"), "--no-cache"]
    _fleet(logs, crossing=0)
    assert run_cli(*argv, "--jobs", "1", "--report", str(report))[0] == 1
    before = report.read_bytes()

    # the next day's logs: the other robots cross; the run stops after two of its pages
    _fleet(logs, crossing=1)
    render = view_module.render_html
    drawn: list[Any] = []

    def stopped_after_two(scene: Any) -> str:
        if len(drawn) == 2:
            raise KeyboardInterrupt
        drawn.append(scene)
        return render(scene)

    monkeypatch.setattr(view_module, "render_html", stopped_after_two)
    assert run_cli(*argv, "--jobs", "1", "--report", str(report))[0] == 130
    assert report.read_bytes() == before
    links = _links(report)
    assert len(links) == 6
    for log, page in links.items():  # every link still leads to its own log's page
        robot = int(Path(log).parent.name[1:])
        assert _first_x(page) == pytest.approx(1 + robot / 100)

    # a run that ends keeps only the pages its report links to
    monkeypatch.setattr(view_module, "render_html", render)
    assert run_cli(*argv, "--jobs", "1", "--report", str(report))[0] == 1
    links = _links(report)
    assert sorted(p.name for p in (tmp_path / "fleet.views").iterdir()) == sorted(
        p.name for p in links.values()
    )
    for log, page in links.items():
        robot = int(Path(log).parent.name[1:])
        assert _first_x(page) == pytest.approx(1 + robot / 100)
        assert _page_verdict(page) == ("violated" if robot % 2 == 1 else "inconclusive")
