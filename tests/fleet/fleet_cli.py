"""The CLI run in-process, with bytes on its standard input (the monitor reads a pipe)."""

from __future__ import annotations

import io
import sys

from tlmpc.cli import main


def run_cli(*argv: str, stdin: bytes | None = None) -> tuple[int, str, str]:
    """Exit code, standard output and standard error of ``tlmpc ARGV`` fed ``stdin``."""
    out, err = io.StringIO(), io.StringIO()
    saved = sys.stdin
    if stdin is not None:
        sys.stdin = io.TextIOWrapper(io.BytesIO(stdin), encoding="utf-8")
    try:
        code = main(list(argv), out=out, err=err)
    finally:
        sys.stdin = saved
    return code, out.getvalue(), err.getvalue()
