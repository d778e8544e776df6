"""`tlmpc new -o FILE` ends with the command to check FILE: pasted into a shell, it checks FILE."""

from __future__ import annotations

import io
import re
import shlex
from pathlib import Path

import pytest

from tlmpc.cli import main


@pytest.mark.parametrize(
    "name", ["plain.yaml", "my site.yaml", "it's.yaml", "-dash.yaml", "$HOME*.yaml", 'a"b.yaml']
)
def test_the_suggested_command_names_the_written_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str
) -> None:
    monkeypatch.chdir(tmp_path)
    err = io.StringIO()
    assert main(["new", "patrol", f"--output={name}"], out=io.StringIO(), err=err) == 0
    match = re.search(r"then `(tlmpc check .*)`$", err.getvalue().rstrip("\n"))
    assert match is not None, err.getvalue()
    words = shlex.split(match.group(1))  # what a POSIX shell passes to tlmpc
    assert words[:2] == ["tlmpc", "check"]
    assert len(words) == 3
    assert not words[2].startswith("-")  # a file, not a flag
    assert (tmp_path / words[2]).resolve() == (tmp_path / name).resolve()
    out, check_err = io.StringIO(), io.StringIO()
    assert main(words[1:], out=out, err=check_err) == 0, check_err.getvalue()
