"""``tlmpc monitor --follow`` on standard input: the pipe's end is the input's end.

A followed LOG is polled for growth; a pipe needs no polling (a read waits for its writer)
and, once its writer has closed it, never grows again: the monitor ends there with the
run's verdict, as without ``--follow``."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from fleet_cli import run_cli

import tlmpc.commands.monitor as monitor_command

ROOT = Path(__file__).resolve().parents[2]
MISSION = str(ROOT / "specs" / "reach-avoid.yaml")
#: home, then into the hazard (x in [8, 9], y in [1, 3] in specs/reach-avoid.yaml): violated
POSES = b"t,x,y\n0,1,1\n10,4,2\n20,8.5,2"


class _Clock:
    """The monitor's ``time``: a poll at the end of the input is a test failure, not a wait."""

    monotonic = staticmethod(time.monotonic)

    @staticmethod
    def sleep(seconds: float) -> None:
        raise AssertionError(f"the monitor polled ({seconds} s) at the end of standard input")


@pytest.mark.parametrize("flags", [["--follow"], ["--follow", "--idle", "5"], []])
def test_following_standard_input_ends_with_the_pipe(
    monkeypatch: pytest.MonkeyPatch, flags: list[str]
) -> None:
    monkeypatch.setattr(monitor_command, "time", _Clock())
    code, out, err = run_cli("monitor", "--mission", MISSION, *flags, stdin=POSES)
    assert code == 1, err
    # the last line, without its line break, is read at the pipe's end as without --follow
    assert "<stdin>: violated after 3 poses" in out
