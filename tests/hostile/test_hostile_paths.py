"""Paths no reader can reach — a name longer than the file system allows, a folder the user
may not enter, a loop of symbolic links — are the user's input, answered with U001 (exit 2)
at the path, never an internal error."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest
from hostile_harness import run

ROOT = Path(__file__).resolve().parents[2]
MISSION = ROOT / "specs" / "reach-avoid.yaml"
LOG = ROOT / "specs" / "logs" / "hazard-crossing.csv"

#: One name over the 255 bytes a name may have on Linux file systems.
LONG_NAME = "n" * 300


def _commands(path: Path) -> list[list[str]]:
    """Every command that probes a folder or file it is given before reading it."""
    return [
        ["verify", str(path)],
        ["verify", str(path), str(LOG), "--mission", str(MISSION), "--no-cache"],
        ["export", str(path)],
        ["plot", str(path)],
        ["view", str(path)],
        ["simulate", str(path)],
        ["export-plan", str(path)],
    ]


@pytest.mark.parametrize("argv", _commands(Path("/tmp") / LONG_NAME), ids=lambda a: a[0])
def test_a_name_too_long_is_u001(argv: list[str]) -> None:
    result = run(*argv)
    assert result.code == 2, result.err
    assert "Traceback" not in result.err
    assert "internal error" not in result.err
    assert result.codes() == ["U001"], result.err


def test_the_diagnostic_names_the_path_and_why(tmp_path: Path) -> None:
    folder = tmp_path / LONG_NAME
    result = run("export", str(folder))
    assert result.code == 2
    assert result.codes() == ["U001"]
    first = result.err.splitlines()[0]
    assert first.startswith(f"{folder}")
    assert "File name too long" in first
    assert "  hint: a name in the path is longer than the file system allows" in result.err


def test_the_json_envelope_carries_u001_with_its_file(tmp_path: Path) -> None:
    trace = tmp_path / (LONG_NAME + ".json")
    result = run("verify", str(trace), "--json")
    envelope = json.loads(result.out)
    assert envelope["exit_code"] == 2
    (diagnostic,) = envelope["diagnostics"]
    assert diagnostic["code"] == "U001"
    assert diagnostic["file"].startswith(str(tmp_path))
    assert diagnostic["hint"]


def test_an_image_name_too_long_in_a_map_is_u001(tmp_path: Path) -> None:
    map_yaml = tmp_path / "map.yaml"
    map_yaml.write_text(
        f"image: {LONG_NAME}.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.25\n"
    )
    result = run("import-map", str(map_yaml), "-o", str(tmp_path / "mission.yaml"))
    assert result.code == 2, result.err
    assert "error[U090]" not in result.err
    assert not (tmp_path / "mission.yaml").exists()


@pytest.mark.skipif(os.geteuid() == 0, reason="root enters every folder")
def test_a_folder_the_user_may_not_enter_is_u001(tmp_path: Path) -> None:
    locked = tmp_path / "locked"
    locked.mkdir()
    (locked / "trace.json").write_text("{}")
    locked.chmod(0)
    try:
        for argv in [*_commands(locked / "out"), ["verify", str(locked / "trace.json")]]:
            result = run(*argv)
            assert result.code == 2, (argv, result.err)
            assert "error[U090]" not in result.err
    finally:
        locked.chmod(0o700)


def test_a_folder_the_user_may_not_enter_is_u001_whoever_runs_the_test(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # as root every folder opens: the kernel's answer to another user is given by the probe
    locked = tmp_path / "locked"
    real_stat = Path.stat

    def refused(path: Path, **kwargs: bool) -> os.stat_result:
        if path == locked or locked in path.parents:
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        return real_stat(path, **kwargs)

    monkeypatch.setattr(Path, "stat", refused)  # what is_dir, is_file and exists ask
    result = run("export", str(locked / "out"))
    assert result.code == 2, result.err
    place, _, message = result.err.partition(": error[U001]: ")
    assert Path(place) == locked / "out" or locked in Path(place).parents, result.err
    assert message.startswith(f"cannot access {place}: Permission denied"), result.err
    assert "hint: you have no permission to enter a folder of the path" in result.err


def test_compiling_a_mission_that_is_a_link_loop_is_u001(tmp_path: Path) -> None:
    (tmp_path / "a.yaml").symlink_to(tmp_path / "b.yaml")
    (tmp_path / "b.yaml").symlink_to(tmp_path / "a.yaml")
    result = run("compile", str(tmp_path / "a.yaml"), "-o", str(tmp_path / "out"))
    assert result.code == 2, result.err
    assert result.codes() == ["U001"]
    assert "symbolic links" in result.err
    assert not (tmp_path / "out").exists()


def test_a_mission_inside_out_is_still_refused_through_a_link(tmp_path: Path) -> None:
    project = tmp_path / "project"
    project.mkdir()
    (project / "mission.yaml").write_text(MISSION.read_text())
    (tmp_path / "link.yaml").symlink_to(project / "mission.yaml")
    result = run("compile", str(tmp_path / "link.yaml"), "-o", str(project), "--force")
    assert result.code == 2
    assert result.codes() == ["U031"]
    assert (project / "mission.yaml").read_text() == MISSION.read_text()
