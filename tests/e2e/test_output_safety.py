"""Output folders never lose or clobber a user's file: markers, locks, links, signals, errors."""

from __future__ import annotations

import errno
import io
import os
import signal
import stat
from pathlib import Path

import pytest

from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.io import outdir as output
from tlmpc.io.outdir import (
    MARKER,
    check_destination,
    commit,
    output_lock,
    replace_file,
    staging_directory,
    write_artifacts,
)

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "example1.yaml"


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def compile_to(out: Path, *extra: str) -> tuple[int, str, str]:
    return run_cli("compile", str(SPEC), "-o", str(out), "--until", "load", "-q", *extra)


def snapshot(directory: Path) -> dict[str, bytes | str]:
    result: dict[str, bytes | str] = {}
    for path in sorted(directory.rglob("*")):
        key = str(path.relative_to(directory))
        result[key] = "<dir>" if path.is_dir() else path.read_bytes()
    return result


def test_artifact_names_alone_do_not_make_an_output(tmp_path: Path) -> None:
    out = tmp_path / "photos"
    out.mkdir()
    (out / "plan.png").write_bytes(b"my own picture")
    (out / "trace.json").mkdir()
    (out / "trace.json" / "notes.txt").write_text("mine")
    before = snapshot(out)
    code, _, err = compile_to(out)
    assert code == 2
    assert err.startswith(f"{out}: error[U012]"), err  # placed at the -o path
    assert snapshot(out) == before


def test_compiling_a_mission_inside_out_is_refused(tmp_path: Path) -> None:
    project = tmp_path / "proj"
    project.mkdir()
    mission = project / "mission.json"
    mission.write_bytes(SPEC.read_bytes())
    for extra in ((), ("--force",)):
        code, _, err = run_cli("compile", str(mission), "-o", str(project), "-q", *extra)
        assert code == 2
        assert "error[U01" in err or "error[U031]" in err
        assert mission.read_bytes() == SPEC.read_bytes()
    # Even a marked output is not swapped away while it holds the source.
    (project / MARKER).write_text("tlmpc.io.outdir/1\n")
    source = project / "src.yaml"
    source.write_bytes(SPEC.read_bytes())
    code, _, err = run_cli("compile", str(source), "-o", str(project), "-q", "--until", "load")
    assert code == 2
    assert "error[U031]" in err
    assert source.read_bytes() == SPEC.read_bytes()


def test_force_never_replaces_a_folder_named_like_an_artifact(tmp_path: Path) -> None:
    out = tmp_path / "mixed"
    out.mkdir()
    (out / "mission.json").mkdir()
    (out / "mission.json" / "keep.txt").write_text("mine")
    code, _, err = compile_to(out, "--force")
    assert code == 2
    assert "error[U031]" in err
    assert (out / "mission.json" / "keep.txt").read_text() == "mine"


def test_symlinked_out_is_refused_and_its_target_untouched(tmp_path: Path) -> None:
    target = tmp_path / "real"
    target.mkdir()
    (target / "thesis.tex").write_text("precious")
    link = tmp_path / "link"
    link.symlink_to(target)
    for extra in ((), ("--force",)):
        code, _, err = compile_to(link, *extra)
        assert code == 2
        assert "error[U030]" in err
        assert link.is_symlink()
        assert snapshot(target) == {"thesis.tex": b"precious"}


def test_second_run_on_a_locked_out_gets_a_clear_error(tmp_path: Path) -> None:
    out = tmp_path / "out"
    with output_lock(out):
        code, _, err = compile_to(out)
    assert code == 2
    assert "error[U032]" in err
    assert not out.exists()
    code, _, err = compile_to(out)  # the lock is gone with the run that held it
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_stale_folders_of_killed_runs_are_cleaned_or_restored(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert compile_to(out)[0] == 0
    stale = tmp_path / ".out.tlmpc-new-killed"
    stale.mkdir()
    (stale / MARKER).write_text("tlmpc.io.outdir/1\n")
    foreign = tmp_path / ".out.tlmpc-new-notours"
    foreign.mkdir()
    (foreign / "data.txt").write_text("mine")
    code, _, err = compile_to(out, "--force")
    assert code == 0
    assert not stale.exists()
    assert (foreign / "data.txt").read_text() == "mine"
    assert "left" in err
    # A run killed between the two renames of the fallback swap left OUT in "-old".
    previous = snapshot(out)
    moved = tmp_path / ".out.tlmpc-old-killed"
    out.rename(moved)
    code, _, err = run_cli("plot", str(out))  # a reader does not repair; the next compile does
    assert code == 2
    broken = tmp_path / "broken.yaml"
    broken.write_text("version: 1\n")
    code, _, err = run_cli("compile", str(broken), "-o", str(out), "-q")
    assert code == 1  # the run fails, but first it put the previous output back
    assert "restored" in err
    assert not moved.exists()
    assert snapshot(out) == previous


def _previous_output(out: Path) -> dict[str, bytes | str]:
    out.mkdir()
    (out / MARKER).write_text("tlmpc.io.outdir/1\n")
    (out / "summary.json").write_text("old")
    return snapshot(out)


@pytest.mark.parametrize("exchange", [True, False])
def test_a_signal_during_the_swap_waits_until_out_is_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, exchange: bool
) -> None:
    out = tmp_path / "out"
    _previous_output(out)
    real_rename = os.rename
    real_exchange = output._exchange

    def interrupted_exchange(a: Path, b: Path) -> bool:
        os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C right inside the swap
        return real_exchange(a, b) if exchange else False

    def interrupted_rename(a: str | Path, b: str | Path) -> None:
        os.kill(os.getpid(), signal.SIGINT)
        real_rename(a, b)

    monkeypatch.setattr(output, "_exchange", interrupted_exchange)
    monkeypatch.setattr(os, "rename", interrupted_rename)

    def run() -> None:
        with staging_directory(out) as staging:
            write_artifacts(staging, {"summary.json": "new"})
            commit(staging, out, force=False)

    with pytest.raises(KeyboardInterrupt):
        run()
    monkeypatch.undo()
    assert (out / "summary.json").read_text() == "new"
    assert (out / MARKER).is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


@pytest.mark.parametrize("removal", ["_release_lock", "_remove_staging"])
def test_a_second_signal_before_a_removal_leaves_nothing_behind(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, removal: str
) -> None:
    # SIGTERM before the commit, and a second one landing in the ``finally`` that removes the
    # lock (or the staging folder), just before the removal: the run still ends 143 with
    # nothing of its own left beside OUT
    real = getattr(output, removal)
    calls: list[Path] = []

    def cut_short(path: Path, *rest: int) -> None:
        calls.append(path)
        if len(calls) == 1:
            signal.raise_signal(signal.SIGTERM)
        real(path, *rest)

    def terminated(*arguments: object, **keywords: object) -> None:
        signal.raise_signal(signal.SIGTERM)

    monkeypatch.setattr(output, removal, cut_short)
    monkeypatch.setattr(output, "commit", terminated)
    out = tmp_path / "out"
    code, _, err = compile_to(out)
    assert (code, err) == (143, "tlmpc: terminated\n")
    assert len(calls) == 2  # the cut-short removal, then the one after the run
    assert list(tmp_path.iterdir()) == []
    assert output.held() == frozenset()


def test_the_redelivery_alarm_while_the_lock_is_taken_leaves_no_lock(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The command line delivers again, by SIGALRM a moment later, a signal whose exception a
    # finaliser swallowed; that alarm once landed just after the lock file was opened, before
    # the run knew it held the lock, and the lock file outlived the run.
    real = output._take_lock

    def alarm_at_once(out: Path, lock: Path) -> int:
        descriptor = real(out, lock)
        signal.raise_signal(signal.SIGALRM)
        return descriptor

    monkeypatch.setattr(output, "_take_lock", alarm_at_once)
    code, _, err = compile_to(tmp_path / "out")
    assert (code, err) == (130, "tlmpc: interrupted\n")
    assert list(tmp_path.iterdir()) == []


def test_a_run_inside_a_run_leaves_the_enclosing_lock_held(tmp_path: Path) -> None:
    # the run after a signal removes what it left, never what its caller still holds
    out, other = tmp_path / "out", tmp_path / "other"
    with output_lock(out):
        held = output.held()
        with staging_directory(out) as staging:
            code, _, err = compile_to(other)
            assert code == 0, err
            assert output.held() == held | {staging}
    assert output.held() == frozenset()


def test_the_redelivery_alarm_waits_until_a_deferred_block_ends(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # the command line's alarm re-raises a signal a finaliser swallowed; inside a block that
    # takes the lock or makes the staging folder it must wait like the signal itself
    class Alarm(Exception):
        pass

    def ring(number: int, frame: object) -> None:
        raise Alarm

    def block_and_ring(finished: list[bool]) -> None:
        with output._signals_blocked():
            signal.raise_signal(signal.SIGALRM)
            finished.append(True)

    previous = signal.signal(signal.SIGALRM, ring)
    finished: list[bool] = []
    try:
        with pytest.raises(Alarm):
            block_and_ring(finished)
    finally:
        signal.signal(signal.SIGALRM, previous)
    assert finished == [True]


def test_outputs_get_umask_permissions(tmp_path: Path) -> None:
    previous = os.umask(0o022)
    try:
        out = tmp_path / "out"
        assert compile_to(out)[0] == 0
        assert stat.S_IMODE(out.stat().st_mode) == 0o755
        for path in out.iterdir():
            assert stat.S_IMODE(path.stat().st_mode) == 0o644, path
        model = tmp_path / "model.dot"
        replace_file(model, b"graph D {}\n")
        assert stat.S_IMODE(model.stat().st_mode) == 0o644
        model.chmod(0o600)
        replace_file(model, b"graph D { }\n")
        assert stat.S_IMODE(model.stat().st_mode) == 0o600  # a replaced file keeps its mode
    finally:
        os.umask(previous)


def test_replace_file_refuses_links_devices_and_folders(tmp_path: Path) -> None:
    target = tmp_path / "target.txt"
    target.write_text("mine")
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    folder = tmp_path / "folder"
    folder.mkdir()
    for path in (link, folder, Path("/dev/null")):
        with pytest.raises(UsageError) as caught:
            replace_file(path, b"x")
        assert caught.value.diagnostics[0].code == "U034"
    assert target.read_text() == "mine"
    assert link.is_symlink()
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


def test_export_and_plot_refuse_non_regular_targets(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert run_cli("compile", str(SPEC), "-o", str(out), "--until", "abstraction", "-q")[0] == 0
    code, _, err = run_cli("export", str(out), "--format", "dot", "-o", "/dev/null")
    assert code == 2
    assert "error[U034]" in err
    (out / "plan.png").mkdir()
    code, _, err = run_cli("plot", str(out), "--format", "png")
    assert code == 2
    assert "error[U034]" in err


@pytest.mark.parametrize(
    ("code", "words"),
    [(errno.ENOSPC, "disk is full"), (errno.EROFS, "read-only"), (errno.EACCES, "permission")],
)
def test_io_errors_on_the_output_path_are_u033(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, code: int, words: str
) -> None:
    out = tmp_path / "out"
    before = _previous_output(out)

    def failing(path: Path, content: object) -> None:
        raise OSError(code, os.strerror(code), str(path))

    monkeypatch.setattr(output, "_write", failing)
    exit_code, _, err = compile_to(out)
    assert exit_code == 2
    assert "error[U033]" in err
    assert words in err
    assert snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_unwritable_places_are_u_codes(tmp_path: Path) -> None:
    code, _, err = compile_to(Path("/proc/tlmpc-out"))
    assert code == 2
    assert "error[U03" in err
    code, _, err = compile_to(Path("/"))
    assert code == 2
    assert err.startswith("/: error[U011]"), err
    code, _, err = compile_to(tmp_path / "missing" / "out")
    assert code == 2
    assert err.startswith(f"{tmp_path / 'missing' / 'out'}: error[U010]"), err


def test_check_destination_rejects_files(tmp_path: Path) -> None:
    target = tmp_path / "file"
    target.write_text("x")
    with pytest.raises(UsageError) as caught:
        check_destination(target, force=True)
    assert caught.value.diagnostics[0].code == "U011"


def test_a_users_file_in_a_previous_output_is_never_deleted(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert run_cli("compile", str(SPEC), "-o", str(out), "-q", "--until", "plan")[0] == 0
    assert (out / "witness.json").is_file()
    (out / "notes.md").write_text("my notes")
    (out / "run1").mkdir()
    (out / "run1" / "robot.bag").write_bytes(b"a log")
    before = snapshot(out)
    code, _, err = compile_to(out)
    assert code == 2
    assert err.startswith(f"{out}: error[U012]"), err
    assert "notes.md, run1" in err
    assert snapshot(out) == before  # nothing replaced, nothing deleted
    with pytest.raises(UsageError) as caught:  # known before any stage runs
        output.refuse_deleting_foreign(out, force=False)
    assert caught.value.diagnostics[0].code == "U012"
    output.refuse_deleting_foreign(out, force=True)
    # with --force the artifacts are replaced one by one: the user's files stay, the previous
    # run's artifacts this one does not write go (they would be taken for its own)
    code, _, err = compile_to(out, "--force")
    assert code == 0, err
    assert (out / "notes.md").read_text() == "my notes"
    assert (out / "run1" / "robot.bag").read_bytes() == b"a log"
    assert (out / MARKER).is_file()
    assert (out / "mission.json").is_file()
    assert not (out / "witness.json").exists()


def test_what_tlmpc_writes_into_an_output_is_replaced_whole(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert run_cli("compile", str(SPEC), "-o", str(out), "-q", "--until", "plan")[0] == 0
    (out / "view.html").write_text("<html></html>")  # `tlmpc view out` writes it there
    assert compile_to(out)[0] == 0
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "mission.json", "summary.json"]


def test_a_users_file_arriving_during_the_run_is_kept(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert compile_to(out)[0] == 0
    with staging_directory(out) as staging:
        write_artifacts(staging, {"summary.json": {"format": "x"}})
        (out / "notes.md").write_text("mine")  # after the checks, before the swap
        with pytest.raises(UsageError) as caught:
            commit(staging, out, force=False)
    assert caught.value.diagnostics[0].code == "U012"
    assert (out / "notes.md").read_text() == "mine"
