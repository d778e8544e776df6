"""The runtime executor behind a line protocol, for a robot's process that cannot import tlmpc.

``python -m tlmpc.runtime.bridge OUT`` loads the compiled output ``OUT`` and speaks JSON lines
(one JSON object per line, UTF-8) on standard input and output.  The first line it writes says
who it is::

    {"format": "tlmpc.bridge/1", "model": "unicycle", "pose": ["x", "y", "yaw"],
     "command": ["v", "omega"], "max_speed": 0.5, "mission": "depot"}

Then, for every line it reads, ``{"t": 12.5, "pose": [x, y, yaw]}`` (a point robot's pose is
``[x, y]``; poses in the mission's frame, ``t`` in seconds, any origin, never decreasing), it
writes one line, the command and the progress::

    {"t": 12.5, "command": [0.31, -0.12], "status": "following", "step": 7, "phase": "prefix",
     "laps": 0, "visits": {"dock": 1}, "replans": 0, "reentries": 0}

``command`` is ``[vx, vy]`` for a point robot and ``[v, omega]`` for a unicycle; it is zero
when the status says the task cannot go on (``no_plan``, ``violated``).  A line that is not
such a request gets ``{"error": {"code": ..., "message": ..., "hint": ...}}`` instead (U120 not
a request, U121 longer than :data:`MAX_LINE` bytes, R023 not a finite pose), and the bridge
reads on: the robot's side must stop the robot on an error.  Blank lines are skipped.  At the
end of its input the bridge exits 0; when ``OUT`` cannot be loaded it prints the diagnostic
on standard error and exits 2 before writing anything; Ctrl-C and SIGTERM end it with 130 and
143.

Why a bridge: a ROS 2 distribution runs its nodes with the system's Python (3.10 on Ubuntu
22.04 and ROS 2 Humble), which cannot import tlmpc; the node starts the bridge with tlmpc's
own interpreter and talks to it through a pipe (``tools/ros2/tlmpc_bridge_node.py``).
"""

from __future__ import annotations

import json
import signal
import sys
from collections.abc import Sequence
from typing import IO, Any

from tlmpc.base.errors import Diagnostic, TlmpcError, error
from tlmpc.base.startup import EXIT_INTERRUPTED, EXIT_TERMINATED
from tlmpc.runtime.executor import Executor

#: The format of the bridge's first line.
BRIDGE_FORMAT = "tlmpc.bridge/1"

#: The longest request line, in bytes (a pose is some 60).
MAX_LINE = 64 * 1024


def hello(executor: Executor) -> dict[str, Any]:
    """The bridge's first line: the protocol, the robot's model and what its lines hold."""
    unicycle = executor.is_unicycle
    return {
        "format": BRIDGE_FORMAT,
        "model": executor.mission.robot.model,
        "pose": ["x", "y", "yaw"] if unicycle else ["x", "y"],
        "command": ["v", "omega"] if unicycle else ["vx", "vy"],
        "max_speed": executor.mission.robot.max_speed,
        "mission": executor.mission.name,
    }


#: The reply to a line longer than :data:`MAX_LINE` (newline included).
TOO_LONG = {
    "error": {
        "code": "U121",
        "message": f"a request line of more than {MAX_LINE:,} bytes",
        "hint": 'one request per line: {"t": T, "pose": [x, y, yaw]}',
    }
}


def answer(executor: Executor, line: bytes) -> dict[str, Any]:
    """The reply to one request line (an ``error`` object for a bad one)."""
    if len(line) > MAX_LINE:
        return TOO_LONG
    try:
        request = json.loads(line)
    except ValueError:
        request = None
    if (
        not isinstance(request, dict)
        or not isinstance(request.get("pose"), list)
        or not all(_is_number(v) for v in request["pose"])
        or not _is_number(request.get("t"))
    ):
        return _error(
            error(
                "U120",
                "a request is a JSON object with a number `t` and a list of numbers `pose`",
                hint='e.g. {"t": 12.5, "pose": [1.0, 2.0, 0.3]} on one line',
            )
        )
    t = float(request["t"])
    try:
        command = executor.command([float(v) for v in request["pose"]], t)
    except TlmpcError as exc:
        return _error(exc.diagnostics[0])
    progress = executor.progress
    return {
        "t": t,
        "command": [command[0], command[1]],
        "status": progress.status,
        "step": progress.step,
        "phase": progress.phase,
        "laps": progress.laps,
        "visits": dict(progress.visits),
        "replans": progress.replans,
        "reentries": progress.reentries,
    }


def serve(executor: Executor, requests: IO[bytes], replies: IO[str]) -> None:
    """Answer every line of ``requests`` on ``replies`` until the end of the input."""
    replies.write(json.dumps(hello(executor)) + "\n")
    replies.flush()
    while True:
        line = requests.readline(MAX_LINE + 2)
        if not line:
            return
        if len(line) > MAX_LINE:
            while line and not line.endswith(b"\n"):  # the rest of the over-long line
                line = requests.readline(MAX_LINE)
            reply = TOO_LONG
        elif not line.strip():
            continue
        else:
            reply = answer(executor, line)
        replies.write(json.dumps(reply) + "\n")
        replies.flush()


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m tlmpc.runtime.bridge OUT``: serve standard input and output."""
    arguments = list(sys.argv[1:] if argv is None else argv)
    if len(arguments) != 1 or arguments[0].startswith("-"):
        sys.stderr.write("usage: python -m tlmpc.runtime.bridge OUT (see its docstring)\n")
        return 2
    signal.signal(signal.SIGTERM, _terminated)
    try:
        try:
            executor = Executor.from_output(arguments[0])
        except TlmpcError as exc:
            for diagnostic in exc.diagnostics:
                sys.stderr.write(diagnostic.format() + "\n")
            return exc.exit_code
        serve(executor, sys.stdin.buffer, sys.stdout)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except _Terminated:
        return EXIT_TERMINATED
    except BrokenPipeError:
        return 0  # the robot's side went away: nothing more to answer
    return 0


class _Terminated(BaseException):
    """SIGTERM: unwind like Ctrl-C."""


def _terminated(number: int, frame: object) -> None:
    raise _Terminated


def _error(diagnostic: Diagnostic) -> dict[str, Any]:
    return {"error": {k: v for k, v in diagnostic.to_json().items() if k != "severity"}}


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


if __name__ == "__main__":
    raise SystemExit(main())
