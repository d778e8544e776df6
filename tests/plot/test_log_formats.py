"""`plot --log` and `view --log` read every log format `verify` reads, the same way.

One log written as a CSV, a ROS 1 bag, ROS 2 bags (sqlite3 and MCAP) and a bare .mcap file
(with `rosbags`, stamped with a robot's clock): each command reads each form, and the verdict
`plot` marks and the one `view` shows are `verify`'s own on that form.
"""

from __future__ import annotations

import io
import json
import re
from pathlib import Path
from typing import Any

import pytest
from robot_data import require_shared, write_bag

from tlmpc.cli import main

pytest.importorskip("rosbags")

MISSION = """\
version: 1
name: yard
workspace:
  boundary: {rect: [0, 0, 10, 6]}
  holes: [{rect: [4, 2, 5, 4]}]
regions:
  dock: {rect: [8, 4, 9.5, 5.5]}
  hazard: {rect: [6, 0, 7, 2.5]}
robot: {start: [1, 1], max_speed: 1.0}
task: [visit dock, avoid hazard]
"""
START_NS = 1_700_000_000_000_000_000  # a robot's wall clock
#: (seconds from the start, x, y): into the hazard, then to the dock
ROWS = [(0.0, 1.0, 1.0), (4.0, 3.5, 1.0), (8.0, 6.5, 1.5), (12.0, 8.0, 3.0), (16.0, 8.8, 4.8)]


def _run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def setup(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict[str, Path]]:
    work = tmp_path_factory.mktemp("formats")
    mission = work / "yard.yaml"
    mission.write_text(MISSION)
    out = work / "out"
    assert _run("compile", str(mission), "-o", str(out), "-q")[0] == 0
    rows = [(START_NS + int(t * 1e9), x, y) for t, x, y in ROWS]
    forms: dict[str, Path] = {}
    csv = work / "run.csv"
    csv.write_text("t,x,y\n" + "".join(f"{ns / 1e9!r},{x},{y}\n" for ns, x, y in rows))
    forms["csv"] = csv
    forms["ros1"] = write_bag(work / "run.bag", "ros1", {"/odom": ("nav_msgs/msg/Odometry", rows)})
    for kind in ("sqlite3", "mcap"):
        forms[kind] = write_bag(
            work / f"run_{kind}", kind, {"/odom": ("nav_msgs/msg/Odometry", rows)}
        )
    forms["bare mcap"] = next(forms["mcap"].glob("*.mcap"))
    return mission, out, forms


def _verify(path: Path, mission: Path, *flags: str) -> dict[str, Any]:
    code, text, _ = _run("verify", str(path), "--mission", str(mission), "--json", *flags)
    assert code == 1  # the log enters the hazard
    result: dict[str, Any] = json.loads(text)["result"]
    return result


@pytest.mark.parametrize("form", ["csv", "ros1", "sqlite3", "mcap", "bare mcap"])
def test_plot_reads_every_log_verify_reads(
    setup: tuple[Path, Path, dict[str, Path]], form: str
) -> None:
    mission, out, forms = setup
    expected = _verify(forms[form], mission)
    code, text, err = _run("plot", str(out), "--log", str(forms[form]), "--json")
    assert code == 0, err
    result = json.loads(text)["result"]
    assert result["verdict"] == expected
    svg = (out / "log.svg").read_text()
    # the verifier's message, relative to the log's start with the stamp beside, is in the legend
    words = " ".join(re.findall(r">([^<]+)</text>", svg))
    assert re.search(r"entered hazard at t=7\.333 s \(stamp 1700000007\.333\)", words), words


@pytest.mark.parametrize("form", ["csv", "ros1", "sqlite3", "mcap", "bare mcap"])
def test_view_reads_every_log_verify_reads(
    setup: tuple[Path, Path, dict[str, Path]], form: str, tmp_path: Path
) -> None:
    mission, _, forms = setup
    expected = _verify(forms[form], mission)
    page = tmp_path / "page.html"
    code, _, err = _run(
        "view", "--log", str(forms[form]), "--mission", str(mission), "-o", str(page)
    )
    assert code == 0, err
    html = page.read_text()
    data = html.split('<script id="scene" type="application/json">', 1)[1].split("</script>", 1)[0]
    scene = json.loads(data)
    assert scene["verdict"] == expected
    assert [s[0] for s in scene["trajectory"]] == pytest.approx(
        [START_NS / 1e9 + t for t, _, _ in ROWS], abs=1e-6
    )


def test_a_bag_directory_gets_its_page_beside_it(setup: tuple[Path, Path, dict[str, Path]]) -> None:
    mission, _, forms = setup
    code, _, err = _run("view", "--log", str(forms["sqlite3"]), "--mission", str(mission))
    assert code == 0, err
    assert (forms["sqlite3"].parent / "run_sqlite3.html").is_file()


def test_the_log_flags_are_shared(
    setup: tuple[Path, Path, dict[str, Path]], tmp_path: Path
) -> None:
    mission, out, forms = setup
    rows = [(START_NS + int(t * 1e9), x, y) for t, x, y in ROWS]
    two = write_bag(
        tmp_path / "two.bag",
        "ros1",
        {
            "/odom": ("nav_msgs/msg/Odometry", rows),
            "/pose": ("geometry_msgs/msg/PoseStamped", [(ns, 1.0, 1.0) for ns, _, _ in rows]),
        },
    )
    for argv in (
        ("plot", str(out), "--log", str(two)),
        ("view", "--log", str(two), "--mission", str(mission), "-o", str(tmp_path / "v.html")),
        ("verify", str(two), "--mission", str(mission)),
    ):
        code, _, err = _run(*argv)
        assert code == 2
        assert "M064" in err  # several pose topics: choose one
        code, _, err = _run(*argv, "--topic", "/odom")
        assert code in (0, 1), err
    # --transform moves the log the same way in every command
    shifted = _verify(forms["csv"], mission, "--transform", "0.5,0,0")
    code, text, _ = _run(
        "plot", str(out), "--log", str(forms["csv"]), "--transform", "0.5,0,0", "--json"
    )
    assert code == 0
    assert json.loads(text)["result"]["verdict"] == shifted


def test_the_real_jackal_bag_in_every_form_draws_the_same_log(tmp_path: Path) -> None:
    forms = [
        require_shared(form)
        for form in (
            "bags/jackal_odometry.bag",
            "bags/jackal_odometry_ros2_sqlite3",
            "bags/jackal_odometry_ros2_mcap",
        )
    ]
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nworkspace:\n  boundary: {rect: [-12, -5, 6, 25]}\nregions:\n"
        "  goal: {rect: [-10, 20, -8, 23]}\nrobot: {start: [0, 0]}\ntask: [visit goal]\n"
    )
    scenes = []
    for index, bag in enumerate(forms):
        page = tmp_path / f"{index}.html"
        assert _run("view", "--log", str(bag), "--mission", str(mission), "-o", str(page))[0] == 0
        data = page.read_text().split('type="application/json">', 1)[1].split("</script>", 1)[0]
        scenes.append(json.loads(data))
    assert len(scenes[0]["trajectory"]) == 3060
    assert all(scene["trajectory"] == scenes[0]["trajectory"] for scene in scenes)
    assert all(scene["verdict"] == scenes[0]["verdict"] for scene in scenes)
