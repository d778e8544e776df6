"""A SIGTERM at every point of the command line's own code and of the output's writing.

The timed test (``test_hostile_signals.py``) sends its signals to real processes after chosen
delays, so it finds a window a few bytecodes wide only by luck (it once printed a traceback
from one).  Here the moment is chosen exactly: a profile function raises SIGTERM at the k-th
point of one ``tlmpc compile`` (or ``check``) where Python runs a signal's handler, counting
the points in ``tlmpc/cli.py``, the command's module and ``tlmpc/io/outdir.py``, for every k
until the run ends without it: installing and restoring the handlers, the lock, the staging
folder, the commit and everything after it.

Every run must end one of two ways: exit 143 with ``tlmpc: terminated`` as the last line on
standard error (after what the run had said, if anything) and nothing written (no OUT, no
lock file, no temporary folder); or exit 0, standard error as in a run without a signal and
OUT whole, when the signal came after the output was in place or the run had returned (a
late signal: the run had done its work).  Never an exception out of ``main``, never a
traceback or "Exception ignored", and the process's handlers are given back as they were.
"""

from __future__ import annotations

import io
import json
import signal
import sys
from pathlib import Path
from types import FrameType
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]

#: The files whose points get the signal.
WATCHED = tuple(
    str(ROOT / "tlmpc" / name)
    for name in ("cli.py", "commands/compile.py", "commands/check.py", "io/outdir.py")
)

MISSION = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 4, 4]}
regions:
  goal: {rect: [3, 3, 4, 4]}
robot: {start: [0.5, 0.5], max_speed: 1.0}
task:
  - visit goal
"""


class _SignalAtPoint:
    """A profile function that raises SIGTERM at the k-th point where Python would run a
    signal's handler in a watched file: a function of it starting (or a generator of it
    resuming), and every call a line of it makes to C code (``os.rename``, ``signal.signal``,
    ``len`` ...) returning.  There the handler's exception appears exactly where a real
    signal's would (the interpreter checks for signals when a function starts and after each
    call); a trace function's line events would also raise at points a signal never reaches,
    such as between a ``with`` block's last line and its ``__exit__``."""

    def __init__(self, k: int) -> None:
        self.k = k
        self.points = 0
        self.sent = False  # the k-th point was reached
        self.raised = False  # and the signal raised there (not before the run's handlers)

    def __call__(self, frame: FrameType, event: str, arg: Any) -> None:
        if self.sent or event not in ("call", "c_return"):
            return
        if frame.f_code.co_filename not in WATCHED:
            return
        self.points += 1
        if self.points == self.k:
            self.sent = True
            sys.setprofile(None)
            from tlmpc.base import startup

            # the start-up guard still in place ends the process at once (tested apart:
            # test_hostile_signals.py); in this process it would end pytest
            if signal.getsignal(signal.SIGTERM) is not startup.end_at_once:
                self.raised = True
                signal.raise_signal(signal.SIGTERM)


def _run(tmp_path: Path, command: str, k: int) -> tuple[int, str, Path, _SignalAtPoint]:
    """``tlmpc compile`` (or ``check``) in this process, the signal at the k-th watched point
    (the start-up guard in place beforehand, as in the command's process)."""
    import tlmpc.cli as cli
    from tlmpc.base import startup

    folder = tmp_path / f"{command}{k}"
    folder.mkdir()
    mission = str(tmp_path / "mission.yaml")
    argv = ["compile", mission, "-o", str(folder / "out"), "-q"]
    err = io.StringIO()
    tracer = _SignalAtPoint(k)
    before = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGTERM, startup.end_at_once)
    try:
        sys.setprofile(tracer)
        try:
            code = cli.main(
                argv if command == "compile" else ["check", mission], io.StringIO(), err
            )
        finally:
            sys.setprofile(None)
        # the run's own handlers are gone: after the run the guard's place is taken by "ignore"
        assert signal.getsignal(signal.SIGTERM) == signal.SIG_IGN
        assert signal.getsignal(signal.SIGINT) is before[1]
    finally:
        signal.signal(signal.SIGTERM, before[0])
    return code, err.getvalue(), folder, tracer


@pytest.mark.slow
@pytest.mark.parametrize("command", ["compile", "check"])
def test_a_sigterm_at_every_point_of_the_run_ends_it_cleanly(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    # check writes nothing: its late signals come while the handlers are given back
    (tmp_path / "mission.yaml").write_text(MISSION)
    code, said, folder, tracer = _run(tmp_path, command, 0)  # k = 0: no signal
    assert (code, tracer.sent) == (0, False)
    written = sorted(p.name for p in folder.iterdir())
    whole = {p.name: p.read_bytes() for p in (folder / "out").glob("*")}
    endings: dict[str, list[int]] = {"guard": [], "terminated": [], "late": []}
    k = 0
    while tracer.sent or k == 0:
        k += 1
        code, err, folder, tracer = _run(tmp_path, command, k)
        assert "Traceback" not in capsys.readouterr().err
        left = sorted(p.name for p in folder.iterdir())
        if code == 143:
            # what the run had said before (check's summary line), then the one line
            before, _, after = err.rpartition("tlmpc: terminated\n")
            assert after == "", (k, err)
            assert said.startswith(before), (k, err)
            assert left == [], (k, left)
            endings["terminated"].append(k)
        else:
            assert (code, err) == (0, said), (k, code, err)
            assert left == written, (k, left)
            files = {p.name: p.read_bytes() for p in (folder / "out").glob("*")}
            assert files.keys() == whole.keys(), k
            for name, data in files.items():
                if name.endswith(".json"):
                    json.loads(data)
            if tracer.raised:
                endings["late"].append(k)
            elif tracer.sent:
                endings["guard"].append(k)
    # the signal reached the start, the middle and the end of the run: both endings happened,
    # the late ones after every terminated one (divided by the commit, or by the handlers given
    # back when nothing is written)
    assert endings["terminated"], endings
    assert endings["late"], endings
    assert max(endings["guard"], default=0) < min(endings["terminated"]), endings
    assert max(endings["terminated"]) < min(endings["late"]), endings


@pytest.mark.parametrize("signalled", ["terminated", "interrupted"])
def test_a_signal_redelivered_after_the_run_ended_by_one_is_late(signalled: str) -> None:
    """A run ended by a signal whose exception a finaliser had swallowed arms a redelivery
    (SIGALRM a moment later): once the run is said to have ended, that redelivery is late,
    neither raising again nor saying "tlmpc: terminated" twice (the exact-point test above
    met it under load, the alarm landing before the handlers were given back)."""
    import tlmpc.cli as cli
    from tlmpc.base import settled

    exception = cli._Terminated() if signalled == "terminated" else KeyboardInterrupt()
    err = io.StringIO()
    settled.begin()
    cli._RECEIVED[:] = [signal.SIGTERM if signalled == "terminated" else signal.SIGINT]
    try:
        assert cli._ended_by(exception, err) == (143 if signalled == "terminated" else 130)
        cli._on_redelivery(signal.SIGALRM, None)  # late: returns, raises nothing
        cli._on_sigterm(signal.SIGTERM, None)
        cli._on_sigint(signal.SIGINT, None)
    finally:
        cli._RECEIVED.clear()
        settled.begin()
    assert err.getvalue() == f"tlmpc: {signalled}\n"
