"""The output policy: no command writes over its own input, or over a user's file without
``--force``; every refusal leaves every file as it was."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hostile_harness import (  # noqa: F401 (fixtures, found by their names)
    compiled_fixture,
    compiled_once_fixture,
    room_map_fixture,
    run_hostile,
    work_fixture,
)

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(
    ("command", "target"),
    [
        (["view", "out"], "out/mission.json"),
        (["view", "out"], "out/trace.json"),
        (["export", "out"], "out/abstraction.json"),
        (["export", "out"], "out/mission.json"),
        (["export-plan", "out"], "out/trace.json"),
        (["export-plan", "out", "--format", "geojson"], "out/mission.json"),
        (["export-plan", "out", "--format", "path-mcap"], "out/controllers.json"),
        (["simulate", "out"], "out/controllers.json"),
        (["simulate", "out"], "out/witness.json"),
    ],
)
def test_an_output_naming_an_input_is_refused(
    compiled: Path, work: Path, command: list[str], target: str
) -> None:
    result = run_hostile(work, *command, "-o", target)
    assert result.code == 2
    assert result.codes() == ["U043"]


def test_an_input_reached_through_a_link_is_refused(compiled: Path, work: Path) -> None:
    (work / "alias.json").symlink_to(compiled / "mission.json")
    result = run_hostile(work, "export", "out", "-o", "alias.json")
    assert result.code == 2
    assert result.codes() in (["U043"], ["U034"])  # refused either way, never replaced


def test_view_of_a_log_never_replaces_the_log(compiled: Path, work: Path) -> None:
    log = work / "run.html"  # a log whose .html page would be the log itself
    log.write_text("t,x,y\n0,2,5\n1,2.5,5\n")
    result = run_hostile(
        work, "view", "--log", str(log), "--mission", str(ROOT / "specs" / "patrol.yaml")
    )
    assert result.code == 2
    assert result.codes() == ["U043"]


def test_import_map_never_replaces_its_map_or_image(room_map: Path, work: Path) -> None:
    for target in ("map.yaml", "map.pgm"):
        result = run_hostile(
            work,
            "import-map",
            str(room_map),
            "--region",
            "a",
            "0.3",
            "0.3",
            "0.8",
            "0.8",
            "--task",
            "visit a",
            "-o",
            target,
        )
        assert result.code == 2
        assert result.codes() == ["U043"]


def test_stage_keeps_a_users_folder_without_force(compiled: Path, work: Path) -> None:
    mine = work / "mine"
    mine.mkdir()
    (mine / "trace.json").write_text("my own notes\n")
    result = run_hostile(work, "stage", "simulate", "out", "-o", "mine")
    assert result.code == 2
    assert result.codes() == ["U012"]
    forced = run_hostile(
        work, "stage", "simulate", "out", "-o", "mine", "--force", may_write=["mine"]
    )
    assert forced.code == 0, forced.err
    assert (mine / "trace.json").read_text().startswith("{")
    # a tlmpc output (the marker) takes the stage's files without --force
    again = run_hostile(work, "stage", "simulate", "out", "-o", "out", may_write=["out"])
    assert again.code == 0, again.err


def test_a_refused_write_leaves_no_temporary_file(compiled: Path, work: Path) -> None:
    os.mkdir(work / "trace.json")  # a folder where the trace would go
    result = run_hostile(work, "simulate", "out", "-o", "trace.json")
    assert result.code == 2
    assert result.codes() == ["U083"]
    assert sorted(p.name for p in work.iterdir()) == ["out", "trace.json"]


def _fleet(work: Path) -> tuple[Path, Path, Path]:
    """Two logs and a mission mapping naming the mission file, inside ``work``."""
    logs = work / "logs"
    logs.mkdir()
    for name, x in (("one.csv", 2.0), ("two.csv", 2.5)):
        (logs / name).write_text(f"t,x,y\n0,{x},5\n1,{x + 0.5},5\n")
    mission = work / "patrol.yaml"
    mission.write_bytes((ROOT / "specs" / "patrol.yaml").read_bytes())
    mapping = work / "missions.yaml"
    mapping.write_text(
        "format: tlmpc.fleet-missions/1\nmissions:\n  - {logs: '*.csv', mission: patrol.yaml}\n"
    )
    return logs / "one.csv", mission, mapping


@pytest.mark.parametrize("flag", ["--results", "--report"])
@pytest.mark.parametrize("target", ["logs/one.csv", "patrol.yaml", "missions.yaml"])
def test_a_batch_never_writes_over_its_logs_or_missions(work: Path, flag: str, target: str) -> None:
    _fleet(work)
    result = run_hostile(
        work, "verify", "logs", "--mission", "missions.yaml", "--no-cache", flag, target
    )
    assert result.code == 2
    assert result.codes() == ["U043"]
    assert result.out == ""  # refused before any log is verified


def test_a_batchs_results_and_report_are_two_files(work: Path) -> None:
    _fleet(work)
    argv = ("verify", "logs", "--mission", "patrol.yaml", "--no-cache")
    result = run_hostile(work, *argv, "--results", "r.out", "--report", "./r.out")
    assert result.code == 2
    assert result.codes() == ["U043"]


def test_a_batch_never_replaces_a_fifo_and_keeps_a_files_mode(work: Path) -> None:
    _fleet(work)
    argv = ("verify", "logs", "--mission", "patrol.yaml", "--no-cache")
    os.mkfifo(work / "pipe")
    result = run_hostile(work, *argv, "--results", "pipe")
    assert result.code == 2
    assert result.codes() == ["F007"]
    written = run_hostile(work, *argv, "--results", "r.jsonl", may_write=["r.jsonl"])
    assert written.code in (0, 1, 4), written.err
    umask = os.umask(0)
    os.umask(umask)
    assert (work / "r.jsonl").stat().st_mode & 0o777 == 0o666 & ~umask
    (work / "r.jsonl").chmod(0o640)
    again = run_hostile(work, *argv, "--results", "r.jsonl", may_write=["r.jsonl"])
    assert again.code == written.code
    assert (work / "r.jsonl").stat().st_mode & 0o777 == 0o640
