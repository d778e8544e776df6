"""Atomic output: a run writes all artifacts or leaves OUT exactly as it was."""

from __future__ import annotations

from pathlib import Path

import pytest

from tlmpc.base.errors import UsageError
from tlmpc.io.outdir import (
    MARKER,
    check_destination,
    commit,
    is_tlmpc_output,
    staging_directory,
    write_artifacts,
)


def _snapshot(directory: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(directory.iterdir())}


def test_new_directory_receives_all_artifacts(tmp_path: Path) -> None:
    out = tmp_path / "out"
    check_destination(out, force=False)
    with staging_directory(out) as staging:
        write_artifacts(staging, {"mission.json": {"format": "tlmpc.mission/1"}, "plan.png": b"x"})
        commit(staging, out, force=False)
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "mission.json", "plan.png"]
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no staging leftovers


def test_failure_inside_staging_leaves_previous_output_untouched(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / MARKER).write_text("tlmpc.io.outdir/1\n")
    (out / "summary.json").write_text('{"format": "tlmpc.summary/1"}')
    (out / "trace.json").write_text("old")
    before = _snapshot(out)

    def interrupted_run() -> None:
        with staging_directory(out) as staging:
            write_artifacts(staging, {"trace.json": {"new": True}})
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        interrupted_run()
    assert _snapshot(out) == before
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_previous_output_is_replaced_whole(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / MARKER).write_text("tlmpc.io.outdir/1\n")
    (out / "summary.json").write_text('{"format": "tlmpc.summary/1"}')
    (out / "controllers.json").write_text("stale")
    with staging_directory(out) as staging:
        write_artifacts(staging, {"summary.json": {"format": "tlmpc.summary/1"}})
        commit(staging, out, force=False)
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "summary.json"]


def test_foreign_directory_is_refused_without_force(tmp_path: Path) -> None:
    out = tmp_path / "thesis"
    out.mkdir()
    (out / "chapter1.tex").write_text("precious")
    assert not is_tlmpc_output(out)
    with pytest.raises(UsageError) as caught:
        check_destination(out, force=False)
    assert caught.value.diagnostics[0].code == "U012"


def test_force_adds_files_and_keeps_foreign_ones(tmp_path: Path) -> None:
    out = tmp_path / "thesis"
    out.mkdir()
    (out / "chapter1.tex").write_text("precious")
    check_destination(out, force=True)
    with staging_directory(out) as staging:
        write_artifacts(staging, {"trace.json": {"format": "tlmpc.trace/1"}})
        commit(staging, out, force=True)
    assert (out / "chapter1.tex").read_text() == "precious"
    assert (out / "trace.json").exists()


def test_destination_that_is_a_file_is_refused(tmp_path: Path) -> None:
    target = tmp_path / "out"
    target.write_text("a file")
    with pytest.raises(UsageError):
        check_destination(target, force=True)
