"""The fleet report: verdict counts per robot and day and per conjunct from the generated
fleet's oracle, every violation on the heat map, a working view per log, everything escaped."""

from __future__ import annotations

import io
import re
from collections import Counter
from html.parser import HTMLParser
from pathlib import Path, PurePosixPath

import pytest
from fleet_data import generate, write_missions

from tlmpc.cli import main
from tlmpc.fleet.report import robot_and_day


class Page(HTMLParser):
    """The page's tables (cell texts), SVG heat cells, links and any script."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: list[list[list[str]]] = []
        self.cell: list[str] | None = None
        self.heat: list[int] = []
        self.links: list[str] = []
        self.tags: Counter[str] = Counter()
        self.in_title = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags[tag] += 1
        values = dict(attrs)
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self.cell = []
        elif tag == "a":
            self.links.append(values["href"] or "")
        elif tag == "rect" and values.get("class") == "heat":
            self.heat.append(0)
        elif tag == "title" and self.heat:
            self.in_title = True

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th") and self.cell is not None:
            self.tables[-1][-1].append(" ".join("".join(self.cell).split()))
            self.cell = None
        if tag == "title":
            self.in_title = False

    def handle_data(self, data: str) -> None:
        if self.cell is not None:
            self.cell.append(data + " ")
        if self.in_title:
            self.heat[-1] = int(data.split()[0])


def test_report_of_a_generated_fleet(tmp_path: Path) -> None:
    folder = tmp_path / "logs"
    planted = generate(folder, 30, seed=3)
    mapping = write_missions(tmp_path)
    # A robot whose name is markup: the page must show it, not run it.
    hostile = folder / "<img src=x onerror=alert(1)>" / "2026-11-09"
    hostile.mkdir(parents=True)
    (hostile / 'x"&y.csv').write_text("t,x,y\n0,1,5\n10,11,5\n", encoding="utf-8")
    (tmp_path / "missions.yaml").write_text(
        (tmp_path / "missions.yaml").read_text(encoding="utf-8")
        + "  - {logs: '*.csv', mission: avoid.yaml}\n",
        encoding="utf-8",
    )
    report = tmp_path / "fleet.html"
    out, err = io.StringIO(), io.StringIO()
    code = main(
        [
            "verify",
            str(folder),
            "--mission",
            str(mapping),
            "--report",
            str(report),
            "--no-cache",
            "--jobs",
            "1",
        ],
        out=out,
        err=err,
    )
    assert code == 1, err.getvalue()
    text = report.read_text(encoding="utf-8")
    page = Page()
    page.feed(text)
    assert page.tags["script"] == 0
    assert page.tags["img"] == 0
    assert "&lt;img src=x onerror=alert(1)&gt;" in text
    by_day, per_conjunct, logs = page.tables
    # verdicts per robot and day, from the oracle
    expected: Counter[tuple[str, str, str]] = Counter()
    for item in planted:
        robot, day = item.path.parent.parent.name, item.path.parent.name
        expected[(robot, day, item.verdict)] += 1
    expected[("<img src=x onerror=alert(1)>", "2026-11-09", "violated")] += 1
    days = by_day[0][1:]
    found: Counter[tuple[str, str, str]] = Counter()
    for row in by_day[1:]:
        for day, cell in zip(days, row[1:], strict=True):
            for count, verdict in re.findall(r"(\d+) (\w+)", cell):
                found[(row[0], day, verdict)] += int(count)
    assert found == expected
    violated = sum(1 for p in planted if p.verdict == "violated") + 1
    assert per_conjunct[1][:3] == ["G !lake", str(violated), str(violated)]
    # every located violation is in a heat cell
    assert sum(page.heat) == violated
    # one row per log, each with a view that exists
    assert len(logs) - 1 == len(planted) + 1
    assert len(page.links) == len(planted) + 1
    for link in page.links:
        assert (tmp_path / link).is_file()


@pytest.mark.parametrize(
    ("log", "group", "expected"),
    [
        ("fleet/husky/2026-11-01/run.csv", None, ("husky", "2026-11-01")),
        ("fleet/husky/run-2026-11-01.csv", None, ("husky", "2026-11-01")),
        ("fleet/jackal_2026-11-02.csv", None, ("jackal", "2026-11-02")),
        ("fleet/2026-11-03/jackal/a.csv", None, ("jackal", "2026-11-03")),
        ("fleet/x/a.csv", None, ("x", "undated")),
        ("fleet/r7-d20261101.csv", r"(?P<robot>r\d+)-d(?P<day>\d{8})", ("r7", "20261101")),
    ],
)
def test_robot_and_day(log: str, group: str | None, expected: tuple[str, str]) -> None:
    pattern = re.compile(group) if group else None
    assert robot_and_day(log, PurePosixPath("fleet"), pattern) == expected


@pytest.mark.parametrize("report", [True, False])
def test_a_bad_group_fails_before_verifying(tmp_path: Path, report: bool) -> None:
    generate(tmp_path / "logs", 2)
    mapping = write_missions(tmp_path)
    err, out = io.StringIO(), io.StringIO()
    page = ["--report", str(tmp_path / "r.html")] if report else []
    argv = ["verify", str(tmp_path / "logs"), "--mission", str(mapping), *page]
    code = main(
        [*argv, "--group", "(unclosed"],
        out=out,
        err=err,
    )
    assert code == 2
    assert "F009" in err.getvalue()
    assert out.getvalue() == ""  # not one log verified
    assert not (tmp_path / "r.html").exists()
